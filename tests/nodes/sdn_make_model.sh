#!/usr/bin/env bash
# launch-prefix for sdn_node in tests: writes a tiny model first (unless one newer than the
# clothwind executable exists), then runs the node command that follows.
#   sdn_make_model.sh <model.pt> [clothwind train options...] -- <command...>
#     an initialised (untrained) model: its estimates are meaningless, for plumbing tests;
#   sdn_make_model.sh <model.pt> --toy <dataset dir> [train options...] -- <command...>
#     makes the toy dataset (clothwind make-toy-dataset: stripes at f = 1 + 0.5 v Hz) and trains
#     on it, for tests that check the estimates themselves;
#   sdn_make_model.sh <model.pt> --toy <dataset dir> --half [train options...] -- <command...>
#     the same, trained beside <model.pt> (full/) and exported to it in float16 (clothwind
#     export-model, std calibrated on the toy val split), so the node serves a model as
#     models/sdn.pt is shipped.
set -euo pipefail
model="$1"; shift
toy=""
if [ "${1:-}" = "--toy" ]; then toy="$2"; shift 2; fi
half=0
if [ "${1:-}" = "--half" ]; then half=1; shift; fi
opts=()
while [ $# -gt 0 ] && [ "$1" != "--" ]; do opts+=("$1"); shift; done
[ $# -gt 0 ] && shift  # the "--"

source "$(dirname "$0")/clothwind_cli.sh"
# The model is made again when the CLI or this script is newer, or when it was made with other
# options (a .test file edited without a rebuild would otherwise run against the old model).
# Under a lock: two runs of one test in one build would otherwise train into the same folder at once.
recipe="toy=$toy half=$half ${opts[*]}"
mkdir -p "$(dirname "$model")"
exec 9> "$model.lock"
flock 9
made_with="$(cat "$model.recipe" 2>/dev/null || true)"
if [ ! -f "$model" ] || [ "$cli" -nt "$model" ] || [ "$0" -nt "$model" ] || [ "$made_with" != "$recipe" ]; then
  rm -f "$model.recipe"  # written last: a run stopped midway is made again
  if [ -n "$toy" ]; then
    "$cli" make-toy-dataset --out "$toy" --clips 100 --frames 60 --size 32 --seed 1 >&2
    if [ "$half" = 1 ]; then
      "$cli" train --overwrite --data "$toy" --out "$(dirname "$model")/full" "${opts[@]}" >&2
      "$cli" export-model --overwrite --model "$(dirname "$model")/full/model.pt" --out "$model" --precision float16 \
        --calibrate-std "$toy" >&2
    else
      "$cli" train --overwrite --data "$toy" --out "$(dirname "$model")" "${opts[@]}" >&2
    fi
  else
    "$cli" train --overwrite --init-only --out "$(dirname "$model")" "${opts[@]}" >&2
  fi
  echo "$recipe" > "$model.recipe"
fi
exec 9>&-  # the node does not hold the lock
exec "$@"
