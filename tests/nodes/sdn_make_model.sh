#!/usr/bin/env bash
# launch-prefix for sdn_node in tests: writes a tiny initialised model first (unless one newer
# than the clothwind executable exists), then runs the node command that follows. The estimates of
# such a model are meaningless; the tests check the node's plumbing (stamps, errors, images).
# Usage (as launch-prefix): sdn_make_model.sh <model.pt> [clothwind train options...] -- <command...>
set -euo pipefail
model="$1"; shift
opts=()
while [ $# -gt 0 ] && [ "$1" != "--" ]; do opts+=("$1"); shift; done
[ $# -gt 0 ] && shift  # the "--"

# The clothwind CLI lands in <build>/bin; the build's devel space is on CMAKE_PREFIX_PATH.
cli=""
if [ -n "${CLOTHWIND_BUILD:-}" ] && [ -x "$CLOTHWIND_BUILD/bin/clothwind" ]; then
  cli="$CLOTHWIND_BUILD/bin/clothwind"
else
  IFS=: read -r -a prefixes <<< "${CMAKE_PREFIX_PATH:-}"
  for p in "${prefixes[@]}"; do
    if [ -x "$p/../bin/clothwind" ]; then cli="$p/../bin/clothwind"; break; fi
  done
fi
if [ -z "$cli" ]; then
  echo "sdn_make_model: cannot find the clothwind executable (set CLOTHWIND_BUILD)" >&2
  exit 1
fi
if [ ! -f "$model" ] || [ "$cli" -nt "$model" ] || [ "$0" -nt "$model" ]; then
  "$cli" train --init-only --out "$(dirname "$model")" "${opts[@]}"
fi
exec "$@"
