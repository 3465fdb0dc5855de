#!/usr/bin/env bash
# launch-prefix for replay.launch's player in tests: makes the session bag first (unless one newer
# than the clothwind executable exists), then runs the player command that follows.
# Usage (as launch-prefix): replay_make_bag.sh <bag> [make-session options...] --  <command...>
set -euo pipefail
bag="$1"; shift
opts=()
while [ $# -gt 0 ] && [ "$1" != "--" ]; do opts+=("$1"); shift; done
[ $# -gt 0 ] && shift  # the "--"

source "$(dirname "$0")/clothwind_cli.sh"
# Made again when the CLI or this script is newer, or when made with other options (a .test file
# edited without a rebuild would otherwise replay the old bag).
# Under a lock: two runs of one test in one build (ctest --repeat, a second terminal) would
# otherwise write the same bag at once, and one would replay the other's half-written file.
recipe="${opts[*]}"
mkdir -p "$(dirname "$bag")"
(
  flock 9
  if [ ! -f "$bag" ] || [ "$cli" -nt "$bag" ] || [ "$0" -nt "$bag" ] || [ "$(cat "$bag.recipe" 2>/dev/null || true)" != "$recipe" ]; then
    rm -f "$bag.recipe"  # the recipe is written last: a run stopped midway is made again
    "$cli" make-session --out "$bag" --overwrite "${opts[@]}"
    echo "$recipe" > "$bag.recipe"
  fi
) 9> "$bag.lock"
exec "$@"
