#!/usr/bin/env bash
# CLI test of `clothwind make-session`'s outputs: a --preview that names the bag itself is refused
# before the work (the bag replaced the image, exit 0), and an interrupt midway removes the
# temporary bag (it stayed, hundreds of MB of a large session, until a later run into the same
# name) while the process still ends by the signal.
# Usage: make_session_cli_test.sh CLOTHWIND_BINARY
set -euo pipefail
bin="$1"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
fail() { echo "make_session_cli_test: FAIL: $*" >&2; exit 1; }
cd "$work"
status=0
"$bin" make-session --minutes 0.05 --width 16 --height 16 --out same.png --preview same.png >out.txt 2>&1 || status=$?
[ "$status" -eq 2 ] && grep -q -- "--preview same.png is the bag --out names" out.txt && [ ! -e same.png ] ||
  fail "--preview equal to --out was not refused (status $status): $(cat out.txt)"

# A --preview in a folder not there yet is made, as --out's folder is (it was refused).
"$bin" make-session --minutes 0.05 --width 16 --height 16 --out bags/s.bag --preview previews/p.png >out.txt 2>&1 ||
  fail "make-session --preview previews/p.png: $(cat out.txt)"
[ -f bags/s.bag ] && [ -f previews/p.png ] || fail "make-session wrote $(ls -R)"
rm -rf bags previews

# An existing preview is replaced only with --overwrite, as the bag (it was replaced without a word).
printf 'a photo' >kept.png
status=0
"$bin" make-session --minutes 0.05 --width 16 --height 16 --out new.bag --preview kept.png >out.txt 2>&1 || status=$?
[ "$status" -eq 2 ] && grep -qF -- "--preview: kept.png exists; --overwrite replaces it" out.txt && [ ! -e new.bag ] &&
  [ "$(cat kept.png)" = "a photo" ] || fail "an existing --preview without --overwrite (status $status): $(cat out.txt)"
rm -f kept.png out.txt

# Over an earlier session and its preview (--overwrite): both stay as they were when the run is
# stopped (the preview was replaced at the first frame, beside the old bag).
"$bin" make-session --minutes 0.05 --width 16 --height 16 --out big.bag --preview big.png --seed 1 >out.txt 2>&1 ||
  fail "make-session (the earlier session): $(cat out.txt)"
cp big.bag before.bag.keep
cp big.png before.png.keep
"$bin" make-session --minutes 5 --width 512 --height 512 --out big.bag --preview big.png --seed 9 --overwrite \
  --compression none >out.txt 2>&1 &
pid=$!
# Until the temporary bag holds a few frames (786 kB each, uncompressed): past the first, which the
# preview is.
grown() { [ -n "$(find . -maxdepth 1 -name 'big.bag.tmp-*' -size +2M)" ]; }
for _ in $(seq 200); do
  grown && break
  sleep 0.1
done
grown || { kill "$pid"; fail "no temporary bag of 2 MB after 20 s: $(cat out.txt)"; }
# SIGTERM: a non-interactive shell starts background jobs with SIGINT ignored (the unit test
# covers SIGINT).
kill -TERM "$pid"
status=0
wait "$pid" || status=$?
[ "$status" -eq 143 ] || fail "make-session did not end by SIGTERM (status $status): $(tail -3 out.txt)"
left="$(LC_ALL=C ls)"
[ "$left" = "$(printf 'before.bag.keep\nbefore.png.keep\nbig.bag\nbig.png\nout.txt')" ] ||
  fail "an interrupted make-session left: $left"
cmp -s big.bag before.bag.keep || fail "an interrupted make-session changed the earlier bag"
cmp -s big.png before.png.keep || fail "an interrupted make-session replaced the earlier bag's preview"
echo "make_session_cli_test: OK"
