#!/usr/bin/env bash
# CLI test of `clothwind contact-sheet` on what it refuses before reading a frame: a sheet too large
# to hold in memory (10000 tiles of 1024 px were 31 GB) and index entries of another shape (bare
# nlohmann type errors, naming no file). Usage: contact_sheet_cli_test.sh CLOTHWIND_BINARY
set -euo pipefail
bin="$1"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
fail() { echo "contact_sheet_cli_test: FAIL: $*" >&2; exit 1; }

refused() {  # refused TEXT ARGS...: exits 1 (not a crash), its message holds TEXT, no sheet written
  local text="$1"
  shift
  local status=0
  "$bin" contact-sheet "$work/ds" "$@" >"$work/msg.txt" 2>&1 || status=$?
  [ "$status" -eq 1 ] || fail "contact-sheet $* exited $status: $(cat "$work/msg.txt")"
  grep -qF -- "$text" "$work/msg.txt" || fail "contact-sheet $*: the message lacks '$text': $(cat "$work/msg.txt")"
  [ ! -e "$work/ds/contact_sheet.png" ] || fail "contact-sheet $* wrote a sheet"
}

mkdir -p "$work/ds"
echo '{"format":"clothwind-dataset","version":1,"kind":"toy","clips":[{"name":"a"}]}' > "$work/ds/index.json"
refused "--tiles x --tile-size^2 x 3 bytes" --tiles 10000 --tile-size 1024
echo '{"format":"clothwind-dataset","version":1,"kind":"toy","clips":[{"name":5}]}' > "$work/ds/index.json"
refused "$work/ds/index.json: clips[0].name must be a string"
echo '{"format":"clothwind-dataset","version":1,"kind":"toy","clips":["a"]}' > "$work/ds/index.json"
refused "$work/ds/index.json"
echo "contact_sheet_cli_test: OK"
