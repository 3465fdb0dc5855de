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
recipe="${opts[*]}"
if [ ! -f "$bag" ] || [ "$cli" -nt "$bag" ] || [ "$0" -nt "$bag" ] || [ "$(cat "$bag.recipe" 2>/dev/null || true)" != "$recipe" ]; then
  "$cli" make-session --out "$bag" "${opts[@]}"
  echo "$recipe" > "$bag.recipe"
fi
exec "$@"
