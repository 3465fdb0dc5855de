#!/usr/bin/env bash
# launch-prefix for replay.launch's player in tests: makes the session bag first (unless one newer
# than the clothwind executable exists), then runs the player command that follows.
# Usage (as launch-prefix): replay_make_bag.sh <bag> [make-session options...] --  <command...>
set -euo pipefail
bag="$1"; shift
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
  echo "replay_make_bag: cannot find the clothwind executable (set CLOTHWIND_BUILD)" >&2
  exit 1
fi
if [ ! -f "$bag" ] || [ "$cli" -nt "$bag" ] || [ "$0" -nt "$bag" ]; then
  "$cli" make-session --out "$bag" "${opts[@]}"
fi
exec "$@"
