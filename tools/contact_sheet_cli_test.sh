#!/usr/bin/env bash
# CLI test of `clothwind contact-sheet` on what it refuses before reading a frame: a sheet too large
# to hold in memory (10000 tiles of 1024 px were 31 GB), index entries of another shape (bare
# nlohmann type errors, naming no file) and an --out of another format. Usage:
# contact_sheet_cli_test.sh CLOTHWIND_BINARY
set -euo pipefail
bin="$1"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
fail() { echo "contact_sheet_cli_test: FAIL: $*" >&2; exit 1; }

refused() {  # refused STATUS TEXT ARGS...: exits STATUS (2: the command line, 1: the input; not a
             # crash), its message holds TEXT, no sheet written
  local expected="$1" text="$2"
  shift 2
  local status=0
  "$bin" contact-sheet "$work/ds" "$@" >"$work/msg.txt" 2>&1 || status=$?
  [ "$status" -eq "$expected" ] || fail "contact-sheet $* exited $status: $(cat "$work/msg.txt")"
  grep -qF -- "$text" "$work/msg.txt" || fail "contact-sheet $*: the message lacks '$text': $(cat "$work/msg.txt")"
  [ ! -e "$work/ds/contact_sheet.png" ] || fail "contact-sheet $* wrote a sheet"
}

mkdir -p "$work/ds"
echo '{"format":"clothwind-dataset","version":1,"kind":"toy","clips":[{"name":"a"}]}' > "$work/ds/index.json"
refused 2 "--tiles x --tile-size^2 x 3 bytes" --tiles 10000 --tile-size 1024
echo '{"format":"clothwind-dataset","version":1,"kind":"toy","clips":[{"name":5}]}' > "$work/ds/index.json"
refused 1 "$work/ds/index.json: clips[0].name must be a string"
echo '{"format":"clothwind-dataset","version":1,"kind":"toy","clips":["a"]}' > "$work/ds/index.json"
refused 1 "$work/ds/index.json"
# An --out the sheet cannot be written as (PNG or JPEG by its extension, any case) is refused
# naming --out before a tile is read (it failed after reading every tile, naming
# WriteFrameAtomic); a dataset folder named nan is a name, not a number that is not finite.
"$bin" make-toy-dataset --out "$work/nan" --clips 2 --frames 2 --size 16 >/dev/null 2>&1 ||
  fail "make-toy-dataset failed"
for out in sheet.tiff sheet inf; do
  status=0
  (cd "$work" && "$bin" contact-sheet nan --out "$out" >"$work/msg.txt" 2>&1) || status=$?
  [ "$status" -eq 2 ] || fail "contact-sheet --out $out exited $status: $(cat "$work/msg.txt")"
  grep -qF -- "--out $out: expected a file name ending in .png, .jpg or .jpeg" "$work/msg.txt" ||
    fail "contact-sheet --out $out: the message does not name --out: $(cat "$work/msg.txt")"
  ! grep -q "contact-sheet.*tiles" "$work/msg.txt" || fail "contact-sheet --out $out read tiles: $(cat "$work/msg.txt")"
  [ ! -e "$work/$out" ] || fail "contact-sheet --out $out wrote it"
done
(cd "$work" && "$bin" contact-sheet nan --out sheet.JPEG >"$work/msg.txt" 2>&1) ||
  fail "contact-sheet nan --out sheet.JPEG was refused: $(cat "$work/msg.txt")"
[ -s "$work/sheet.JPEG" ] || fail "contact-sheet --out sheet.JPEG wrote no sheet"
# Written as a JPEG by its extension, whatever its case (a PNG under that name passed the size check).
[ "$(head -c3 "$work/sheet.JPEG" | od -An -tx1 | tr -d ' \n')" = ffd8ff ] ||
  fail "contact-sheet --out sheet.JPEG is not a JPEG: $(head -c8 "$work/sheet.JPEG" | od -An -tx1)"
# A sheet in a folder that does not exist yet is written there, the folder made (as every verb's
# outputs; contact-sheet refused it before 2026-12-07).
"$bin" contact-sheet "$work/nan" --out "$work/sheets/new/s.png" >"$work/msg.txt" 2>&1 ||
  fail "contact-sheet into a new folder: $(cat "$work/msg.txt")"
[ -s "$work/sheets/new/s.png" ] || fail "contact-sheet into a new folder wrote no sheet: $(cat "$work/msg.txt")"
# ...but not below a clip's folder, where it was written once its folder could be made.
status=0
"$bin" contact-sheet "$work/nan" --out "$work/nan/toy-00000/new/s.png" >"$work/msg.txt" 2>&1 || status=$?
[ "$status" -eq 2 ] && grep -q "inside the example folder" "$work/msg.txt" && [ ! -e "$work/nan/toy-00000/new" ] ||
  fail "contact-sheet --out inside a clip's folder (status $status): $(cat "$work/msg.txt")"
# A dataset with nothing to show (no clips; a clip whose frames are missing) writes no sheet and
# leaves none of the folders made for it (an empty one was left behind).
for case in '[]|has no clips' '[{"name":"a","wind":1}]|'"$work/ds/a"; do
  clips="${case%%|*}" text="${case#*|}"
  echo '{"format":"clothwind-dataset","version":1,"kind":"toy","clips":'"$clips"'}' > "$work/ds/index.json"
  status=0
  "$bin" contact-sheet "$work/ds" --out "$work/gone/deeper/s.png" >"$work/msg.txt" 2>&1 || status=$?
  [ "$status" -eq 1 ] && grep -qF -- "$text" "$work/msg.txt" ||
    fail "contact-sheet of clips $clips exited $status without '$text': $(cat "$work/msg.txt")"
  [ ! -e "$work/gone" ] || fail "contact-sheet of clips $clips left the folders made for its sheet: $(cat "$work/msg.txt")"
done
echo "contact_sheet_cli_test: OK"
