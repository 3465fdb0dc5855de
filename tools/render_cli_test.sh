#!/usr/bin/env bash
# CLI test of `clothwind render` on a rerun into a used --out: a bad --start or --fps is refused
# before anything is touched (NaN passed the range check, the frame count overflowed, and the
# earlier run's frames were deleted with exit 0), and zeta.json, the mark of a whole run, is
# written last. Usage: render_cli_test.sh CLOTHWIND_BINARY SOURCE_DIR
set -euo pipefail
bin="$1"
src="$2"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
fail() { echo "render_cli_test: FAIL: $*" >&2; exit 1; }

# (simulate, which makes the input: a day at 0.04 s a frame is 2.16 million frames held in memory,
# refused naming --duration before its --out is made.)
status=0
"$bin" simulate "$src/config/scenes/flag.json" --out "$work/day" --duration 86000 --no-obj >"$work/out.txt" 2>&1 || status=$?
[ "$status" -eq 1 ] && grep -q -- "--duration 86000" "$work/out.txt" && [ ! -e "$work/day" ] ||
  fail "simulate --duration 86000 was not refused before the work: $(cat "$work/out.txt")"
"$bin" simulate "$src/config/scenes/flag.json" --out "$work/sim" --duration 0.2 --max-edge 1 --no-obj >/dev/null
"$bin" render "$work/sim" --out "$work/fr" --count 3 --samples 1 --threads 1 >/dev/null 2>&1
[ -f "$work/fr/000.jpg" ] && [ -f "$work/fr/002.jpg" ] && [ -f "$work/fr/zeta.json" ] || fail "first run incomplete"
before="$(md5sum "$work/fr"/*.jpg "$work/fr/zeta.json")"

for bad in "--start nan" "--start inf" "--start -1" "--fps 1e300" "--fps nan" "--frame-time -1" "--samples 100000000"; do
  status=0
  # shellcheck disable=SC2086
  "$bin" render "$work/sim" --out "$work/fr" $bad --samples 1 --threads 1 >"$work/out.txt" 2>&1 || status=$?
  # Refused, not crashed (a signal is 128 + its number), with a message naming the option.
  [ "$status" -ne 0 ] || fail "render $bad exited 0: $(cat "$work/out.txt")"
  [ "$status" -lt 128 ] || fail "render $bad died with status $status: $(cat "$work/out.txt")"
  option="${bad%% *}"
  grep -q -- "${option#--}" "$work/out.txt" || fail "render $bad: the message does not name ${option#--}: $(cat "$work/out.txt")"
  [ "$(md5sum "$work/fr"/*.jpg "$work/fr/zeta.json")" = "$before" ] || fail "render $bad changed the earlier run's files"
done

# A rerun that fails after it starts writing (frame 1 cannot take its place: a folder holds its
# name) leaves no zeta.json beside its new frame 0 and the earlier run's frame 2.
rm "$work/fr/001.jpg"
mkdir "$work/fr/001.jpg"
if "$bin" render "$work/sim" --out "$work/fr" --seed 2 --count 3 --samples 1 --threads 1 >"$work/out.txt" 2>&1; then
  fail "a rerun that could not write frame 1 exited 0"
fi
[ ! -e "$work/fr/zeta.json" ] || fail "a failed rerun left zeta.json beside a mix of two runs' frames"
# A trajectory whose texture coordinates are all one value (no material extent) is refused
# naming the file (the error named none).
mkdir "$work/flat"
/usr/bin/python3 - "$work/sim/trajectory.cwtraj" "$work/flat/trajectory.cwtraj" <<'PY'
import struct, sys
data = bytearray(open(sys.argv[1], 'rb').read())
nv, nf = struct.unpack_from('<II', data, 12)
uv = 32 + 12 * nf
for i in range(2 * nv):
    struct.pack_into('<f', data, uv + 4 * i, 1e30)
open(sys.argv[2], 'wb').write(data)
PY
if "$bin" render "$work/flat" --out "$work/flat-out" --count 1 --samples 1 --threads 1 >"$work/out.txt" 2>&1; then
  fail "a trajectory without texture extent rendered"
fi
grep -q "$work/flat/trajectory.cwtraj: texture coordinates" "$work/out.txt" || fail "the error does not name the trajectory: $(cat "$work/out.txt")"
echo "render_cli_test: OK"
