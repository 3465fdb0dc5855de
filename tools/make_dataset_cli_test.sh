#!/usr/bin/env bash
# CLI test of `clothwind make-dataset`'s options that belong to one kind or are out of range: each
# is refused naming the option, before --out is made. FlagSim's material spreads given to ClothSim
# (and ClothSim's --materials to FlagSim) ran as if not given while the header recorded them;
# --seed -1 was taken as 2^64-1. Usage: make_dataset_cli_test.sh CLOTHWIND_BINARY
set -euo pipefail
bin="$1"
src="$(cd "$(dirname "$0")/.." && pwd)"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
fail() { echo "make_dataset_cli_test: FAIL: $*" >&2; exit 1; }

refused() {  # refused OPTION_NAMED ARGS...: exits non-zero, names the option, makes no --out
  local named="$1"
  shift
  local status=0
  "$bin" make-dataset --count 1 --out "$work/out" "$@" >"$work/msg.txt" 2>&1 || status=$?
  [ "$status" -ne 0 ] || fail "make-dataset $* exited 0"
  [ "$status" -lt 128 ] || fail "make-dataset $* died with status $status: $(cat "$work/msg.txt")"
  grep -q -- "$named" "$work/msg.txt" || fail "make-dataset $*: the message does not name $named: $(cat "$work/msg.txt")"
  [ ! -e "$work/out" ] || fail "make-dataset $* made its --out folder"
}

# Not the background photos' folder (its contact sheet became a backdrop of the next dataset).
mkdir -p "$work/out"
"$bin" make-toy-dataset --out "$work/photos" --clips 1 --frames 2 --size 16 >/dev/null 2>&1 || fail "make-toy-dataset"
cp "$work/photos/toy-00000/000.jpg" "$work/out/field.jpg"
status=0
"$bin" make-dataset --count 1 --out "$work/out/" --backgrounds "$work/out" >"$work/msg.txt" 2>&1 || status=$?
[ "$status" -eq 2 ] && grep -q -- "--out $work/out/ is the --backgrounds folder" "$work/msg.txt" &&
  [ "$(ls "$work/out")" = field.jpg ] || fail "make-dataset --out the --backgrounds folder (status $status): $(cat "$work/msg.txt")"
rm -rf "$work/out"
refused --area-weight-spread --kind cloth --area-weight-spread 50
refused --bending-spread --kind cloth --bending-spread 2
refused --bending-jitter --kind cloth --bending-jitter 2
refused --materials --kind flag --materials "$work"
refused --seed --seed -1
# Out of range: status 2 (the command line), said before the line naming what it would make,
# once ("make-dataset: error: make-dataset: ..." named the verb twice); --jobs beyond what TBB runs.
for bad in "--count 1 --views 99" "--count -2" "--count 1 --jobs 100000" "--count 1 --wind-min 5 --wind-max 2"; do
  status=0
  # shellcheck disable=SC2086
  "$bin" make-dataset --out "$work/out" $bad >"$work/msg.txt" 2>&1 || status=$?
  named="${bad##--count 1 }"
  says="${named%% *} must be"
  [ "$named" != "${named#--wind-min}" ] && says="expected 0 <= wind_min <= wind_max"
  [ "$status" -eq 2 ] && grep -q -- "$says" "$work/msg.txt" && ! grep -q "simulations x" "$work/msg.txt" &&
    [ "$(grep -c "make-dataset" "$work/msg.txt")" -eq 1 ] && [ ! -e "$work/out" ] ||
    fail "make-dataset $bad (status $status): $(cat "$work/msg.txt")"
done
# A scene of two cloths: make-dataset makes examples of the first; the second was dropped unsaid.
python3 - "$src/config/scenes/flag.json" "$work/two.json" <<'PY'
import re, sys
text = re.sub(r"//[^\n]*", "", open(sys.argv[1]).read())
text = text.replace('"meshes/', '"' + sys.argv[1].rsplit("/", 1)[0] + '/../meshes/')
text = text.replace('"materials/', '"' + sys.argv[1].rsplit("/", 1)[0] + '/../materials/')
start = text.index('"cloths": [') + len('"cloths": [')
end = text.index('"motions"')
cloth = text[start:end].rstrip().rstrip(",").rstrip().rstrip("]")
open(sys.argv[2], "w").write(text[:start] + cloth + "," + cloth + "]," + text[end:])
PY
refused "cloths' holds 2 cloths" --scene "$work/two.json"
# A scene whose wind gusts: its clips' labels said the steady speed while the gusts moved the flag.
python3 - "$src/config/scenes/flag.json" "$work/gusty.json" <<'PY'
import re, sys
text = re.sub(r"//[^\n]*", "", open(sys.argv[1]).read())
text = text.replace('"meshes/', '"' + sys.argv[1].rsplit("/", 1)[0] + '/../meshes/')
text = text.replace('"materials/', '"' + sys.argv[1].rsplit("/", 1)[0] + '/../materials/')
text = text.replace('"wind": {"velocity": [3, 0, 0]}', '"wind": {"velocity": [3, 0, 0], "gusts": {"rate": 0.5, "amplitude": 8}}')
assert '"gusts"' in text
open(sys.argv[2], "w").write(text)
PY
refused "field 'wind' has gusts; make-dataset labels each clip with a steady wind speed" --scene "$work/gusty.json"
refused --jpeg-quality --format png --jpeg-quality 5  # lossless: unused, yet written into the header
# ClothSim from this repository's one fabric (no CLOTHWIND_SHARED_DIR, no --materials) is said: it
# looked like the paper's many-fabric ClothSim. So are cameras 40-50 m from the 1 m cloth, which
# it spans 0.386 px of the 16 px frames at most (clips without a visible cloth went into datasets
# without a word), before the work.
CLOTHWIND_SHARED_DIR="" "$bin" make-dataset --kind cloth --count 1 --views 1 --size 16 --frames 2 --jobs 1 \
  --camera-radius 40:50 --out "$work/one-fabric" >"$work/msg.txt" 2>&1 || fail "a one-fabric ClothSim: $(cat "$work/msg.txt")"
grep -q "warning: ClothSim draws from 1 fabric in .*set CLOTHWIND_SHARED_DIR or give --materials DIR" "$work/msg.txt" ||
  fail "a one-fabric ClothSim was not said: $(cat "$work/msg.txt")"
grep -q "warning: cameras up to 50.04 m away (--camera-radius, --camera-height) see the 1 m cloth over about 0.386 px of the 16 px frame" \
  "$work/msg.txt" || fail "a cloth of a few pixels was not said: $(cat "$work/msg.txt")"
refused --jpeg-quality --format pgm --jpeg-quality 5
refused --warmup --warmup 0.019
# More frames than a label may hold ran for hours, then every example was refused by the index; a
# size whose frames need terabytes of memory, likewise.
# A number that is not finite, for any option (CLI11's range checks let NaN through).
refused "--wind-min: expected a finite number" --wind-min nan
refused "--camera-angle: expected a finite number" --camera-angle nan
refused --frames --frames 100001
refused --frames --frames 100000 --size 4096
# --reindex rebuilds the index under the dataset's own header: any other option was accepted and
# ignored (--count 99 --kind cloth --tracks 9x9 rebuilt the same index, exit 0).
for option in "--count 99" "--kind cloth" "--tracks 9x9" "--size 999" "--seed 7"; do
  status=0
  # shellcheck disable=SC2086
  "$bin" make-dataset --reindex --out "$work/none" $option >"$work/msg.txt" 2>&1 || status=$?
  [ "$status" -ne 0 ] && [ "$status" -lt 128 ] || fail "make-dataset --reindex $option exited $status"
  grep -q -- "${option%% *} is not used by --reindex" "$work/msg.txt" ||
    fail "make-dataset --reindex $option: the message does not name ${option%% *}: $(cat "$work/msg.txt")"
done
echo "make_dataset_cli_test: OK"
