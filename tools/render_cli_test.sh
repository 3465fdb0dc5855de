#!/usr/bin/env bash
# CLI test of `clothwind render` on a rerun into a used --out: a bad --start or --fps is refused
# before anything is touched (NaN passed the range check, the frame count overflowed, and the
# earlier run's frames were deleted with exit 0), and zeta.json, the mark of a whole run, is
# written last; options it would ignore are refused; and of `clothwind simulate`, which makes
# its input (a rerun removes the earlier run's frames and trajectories). Usage:
# render_cli_test.sh CLOTHWIND_BINARY SOURCE_DIR
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
[ "$status" -eq 2 ] && grep -q -- "--duration 86000" "$work/out.txt" && [ ! -e "$work/day" ] ||
  fail "simulate --duration 86000 was not refused before the work: $(cat "$work/out.txt")"
# --duration and --seed given as -1 (once the "not given" sentinels) are refused like any other
# negative, naming the option, before --out is made.
for bad in "--duration -1" "--seed -1 --duration 0.04"; do
  status=0
  # (--max-edge 1: the old code simulated the scene's whole duration, coarse.)
  # shellcheck disable=SC2086
  "$bin" simulate "$src/config/scenes/flag.json" --out "$work/neg" --max-edge 1 $bad --no-obj >"$work/out.txt" 2>&1 || status=$?
  [ "$status" -eq 2 ] && grep -q -- "${bad%% *} must be" "$work/out.txt" && [ ! -e "$work/neg" ] ||
    fail "simulate $bad was not refused before the work (status $status): $(cat "$work/out.txt")"
done
"$bin" simulate "$src/config/scenes/flag.json" --out "$work/sim" --duration 0.2 --max-edge 1 --no-obj >/dev/null
# The mesh simulated is said, and the scene's warnings (here an ArcSim key this simulator ignores,
# which changes the physics) are kept in summary.json as well as said: stderr is lost in a batch.
sed -e "s|\"meshes/|\"$src/config/meshes/|; s|\"materials/|\"$src/config/materials/|; 5a \"friction\": 0.5," \
  "$src/config/scenes/flag.json" >"$work/friction.json"
"$bin" simulate "$work/friction.json" --out "$work/fric" --duration 0.04 --no-obj >/dev/null 2>"$work/out.txt"
grep -q "^simulate: cloths\[0\]: 413 vertices, 768 faces, the OBJ's 63 refined once to edges of at most 0.2 m (from remeshing.size" \
  "$work/out.txt" || fail "simulate did not say the mesh it simulates: $(cat "$work/out.txt")"
/usr/bin/python3 -c 'import json, sys; w = json.load(open(sys.argv[1]))["scene_warnings"]; sys.exit(not (len(w) == 1 and "friction: ArcSim key not supported" in w[0]))' \
  "$work/fric/summary.json" || fail "summary.json does not keep the scene's warning: $(grep -A3 scene_warnings "$work/fric/summary.json")"
# A rerun into the folder of an earlier run: its frame OBJs (here cloth 0's, and cloth 1's of a
# run of two cloths) and its trajectory of cloth 1 go, whether this run writes OBJs or not (with
# --no-obj they stayed beside the new summary, and `render DIR --obj` rendered the old cloth).
"$bin" simulate "$src/config/scenes/flag.json" --out "$work/rerun" --duration 0.08 --max-edge 1 >/dev/null
[ -f "$work/rerun/0002_00.obj" ] || fail "simulate wrote no frame OBJs: $(ls "$work/rerun")"
cp "$work/rerun/0000_00.obj" "$work/rerun/0000_01.obj"
cp "$work/rerun/trajectory.cwtraj" "$work/rerun/trajectory_1.cwtraj"
"$bin" simulate "$src/config/scenes/flag.json" --out "$work/rerun" --duration 0.04 --max-edge 1 >/dev/null 2>"$work/out.txt"
left="$(cd "$work/rerun" && LC_ALL=C ls)"
[ "$left" = "$(printf '0000_00.obj\n0001_00.obj\nsummary.json\ntrajectory.cwtraj')" ] ||
  fail "a shorter rerun left files of the earlier run: $left"
cp "$work/rerun/0000_00.obj" "$work/rerun/0000_01.obj"
cp "$work/rerun/trajectory.cwtraj" "$work/rerun/trajectory_1.cwtraj"
# (and a killed run's temporary, of a pid no process has: it stayed for ever)
echo x >"$work/rerun/trajectory.cwtraj.tmp-999999999-3"
"$bin" simulate "$src/config/scenes/flag.json" --out "$work/rerun" --duration 0.04 --max-edge 1 --no-obj >/dev/null 2>"$work/out.txt"
left="$(cd "$work/rerun" && LC_ALL=C ls)"
[ "$left" = "$(printf 'summary.json\ntrajectory.cwtraj')" ] || fail "a --no-obj rerun left files of the earlier run: $left"
# A bad --param (not a number, unknown, out of range, no '=', given twice) is refused before the
# earlier run is touched: it was refused only after its frames and summary were removed.
for bad in "area_weight=abc" "nosuch=1" "area_weight=-1" "area_weight" "area_weight=0.2 --param area_weight=0.3"; do
  status=0
  # shellcheck disable=SC2086
  "$bin" simulate "$src/config/scenes/flag.json" --out "$work/rerun" --duration 0.04 --max-edge 1 --param $bad \
    >"$work/out.txt" 2>&1 || status=$?
  [ "$status" -eq 2 ] && grep -q -- "--param\|parameter" "$work/out.txt" ||
    fail "simulate --param $bad was not refused naming it (status $status): $(cat "$work/out.txt")"
  left="$(cd "$work/rerun" && LC_ALL=C ls)"
  [ "$left" = "$(printf 'summary.json\ntrajectory.cwtraj')" ] || fail "simulate --param $bad removed the earlier run: $left"
done
# So are a --warmup or --turbulence out of range, or a warm-up that is not whole frames (0.03 s
# at 0.04 s frames ran as 0.04 s), naming the option: they were refused after the earlier run
# was removed, naming no option, or ran and failed steps later ("non-finite force").
for bad in "--warmup 4000" "--warmup nan" "--warmup 0.03" "--turbulence 50,1" "--turbulence 0.1,1e-300" \
           "--turbulence -0.1,10"; do
  status=0
  # shellcheck disable=SC2086
  "$bin" simulate "$src/config/scenes/flag.json" --out "$work/rerun" --duration 0.04 --max-edge 1 $bad \
    >"$work/out.txt" 2>&1 || status=$?
  [ "$status" -ne 0 ] && [ "$status" -lt 128 ] && grep -q -- "${bad%% *}" "$work/out.txt" ||
    fail "simulate $bad was not refused naming it (status $status): $(cat "$work/out.txt")"
  left="$(cd "$work/rerun" && LC_ALL=C ls)"
  [ "$left" = "$(printf 'summary.json\ntrajectory.cwtraj')" ] || fail "simulate $bad removed the earlier run: $left"
done
# A simulation that blows up mid-run names the scene and the cloth (the simulator's message names
# a step and a vertex, neither of which the user can change). 3 g/m^2 in the scene's 3 m/s wind
# overshoots the explicit wind force at step 1.
status=0
"$bin" simulate "$src/config/scenes/flag.json" --out "$work/blowup" --duration 0.2 --max-edge 1 --no-obj \
  --param area_weight=0.003 >"$work/out.txt" 2>&1 || status=$?
[ "$status" -eq 1 ] && grep -q -- "simulate: error: $src/config/scenes/flag.json, cloths\[0\]: .*blew up" "$work/out.txt" ||
  fail "a blow-up did not name the scene and cloth (status $status): $(cat "$work/out.txt")"
if "$bin" render "$work/rerun" --obj --out "$work/rerun-fr" --count 1 --samples 1 --threads 1 >"$work/out.txt" 2>&1; then
  fail "render --obj of a --no-obj run rendered an earlier run's frames"
fi
"$bin" render "$work/sim" --out "$work/fr" --count 3 --samples 1 --threads 1 >/dev/null 2>&1
[ -f "$work/fr/000.jpg" ] && [ -f "$work/fr/002.jpg" ] && [ -f "$work/fr/zeta.json" ] || fail "first run incomplete"
before="$(md5sum "$work/fr"/*.jpg "$work/fr/zeta.json")"
cp "$work/fr/zeta.json" "$work/zeta-3m.json"  # a zeta made for the scene's 3 m x 2 m flag

for bad in "--start nan" "--start inf" "--start -1" "--fps 1e300" "--fps nan" "--frame-time -1" "--samples 100000000"; do
  status=0
  # --samples 1 (a fast render, were it not refused) only beside another option: given twice,
  # CLI11 refused the repetition whatever --samples's range said, and that case could not fail.
  samples="--samples 1"
  case "$bad" in --samples*) samples="" ;; esac
  # shellcheck disable=SC2086
  "$bin" render "$work/sim" --out "$work/fr" $bad $samples --threads 1 >"$work/out.txt" 2>&1 || status=$?
  # Refused, not crashed (a signal is 128 + its number), with a message naming the option.
  [ "$status" -ne 0 ] || fail "render $bad exited 0: $(cat "$work/out.txt")"
  [ "$status" -lt 128 ] || fail "render $bad died with status $status: $(cat "$work/out.txt")"
  # Named as given, dashes and all: --samples beyond its range is also refused by the renderer's
  # own check of zeta ("field 'samples'"), which names no option.
  option="${bad%% *}"
  grep -qF -- "$option" "$work/out.txt" || fail "render $bad: the message does not name $option: $(cat "$work/out.txt")"
  [ "$(md5sum "$work/fr"/*.jpg "$work/fr/zeta.json")" = "$before" ] || fail "render $bad changed the earlier run's files"
done

# A --start past the animation's end (0.2 s): the parser's finite-number check refuses NaN and inf
# before the verb does, so this is the case that reaches the verb's own range check.
status=0
"$bin" render "$work/sim" --out "$work/fr" --start 5 --samples 1 --threads 1 >"$work/out.txt" 2>&1 || status=$?
[ "$status" -ne 0 ] && [ "$status" -lt 128 ] && grep -q -- "--start 5 s is outside the animation's" "$work/out.txt" ||
  fail "render --start 5 on a 0.2 s animation was not refused naming it: $(cat "$work/out.txt")"
[ "$(md5sum "$work/fr"/*.jpg "$work/fr/zeta.json")" = "$before" ] || fail "render --start 5 changed the earlier run's files"

# Options given and then ignored are refused naming them, before --out is touched: --backgrounds
# (only a --zeta names a photo) and --keep-zeta without --zeta, and --seed or --kind beside a
# --zeta (rendered as given). Each ran as if not given.
for bad in "--backgrounds $work" "--keep-zeta" "--zeta $work/zeta-3m.json --seed 2" "--zeta $work/zeta-3m.json --kind cloth"; do
  status=0
  # shellcheck disable=SC2086
  "$bin" render "$work/sim" --out "$work/fr" $bad --count 1 --samples 1 --threads 1 >"$work/out.txt" 2>&1 || status=$?
  [ "$status" -ne 0 ] && [ "$status" -lt 128 ] || fail "render $bad exited $status: $(cat "$work/out.txt")"
  option="${bad##* --}"
  option="${option%% *}"
  case "$bad" in --backgrounds*) option="backgrounds" ;; --keep-zeta) option="keep-zeta" ;; esac
  grep -q -- "--$option" "$work/out.txt" || fail "render $bad: the message does not name --$option: $(cat "$work/out.txt")"
  [ "$(md5sum "$work/fr"/*.jpg "$work/fr/zeta.json")" = "$before" ] || fail "render $bad changed the earlier run's files"
done
# Input options that do not apply to the input are refused naming them: --cloth, --obj and
# --frame-time beside a trajectory file (one cloth, its own times), --frame-time beside a folder's
# trajectory. Each rendered as if not given.
for bad in "$work/sim/trajectory.cwtraj --cloth 3" "$work/sim/trajectory.cwtraj --obj" \
           "$work/sim/trajectory.cwtraj --frame-time 0.1" "$work/sim --frame-time 0.1"; do
  status=0
  # shellcheck disable=SC2086
  "$bin" render $bad --out "$work/fr" --count 1 --samples 1 --threads 1 >"$work/out.txt" 2>&1 || status=$?
  [ "$status" -ne 0 ] && [ "$status" -lt 128 ] || fail "render $bad exited $status: $(cat "$work/out.txt")"
  option="--${bad##* --}"
  option="${option%% *}"
  grep -q -- "$option is for" "$work/out.txt" || fail "render $bad: the message does not name $option: $(cat "$work/out.txt")"
  [ "$(md5sum "$work/fr"/*.jpg "$work/fr/zeta.json")" = "$before" ] || fail "render $bad changed the earlier run's files"
done
# A --zeta naming its background photo by file name needs --backgrounds: it was looked up in the
# current folder ("no such file" naming no option, or another photo of that name rendered).
sed 's/"background_image": *"[^"]*"/"background_image": "sky.png"/' "$work/zeta-3m.json" >"$work/zeta-photo.json"
grep -q '"background_image": "sky.png"' "$work/zeta-photo.json" || fail "no background_image to set in $work/zeta-photo.json"
cp "$work/fr/000.jpg" "$work/sky.png"  # a photo of that name in the current folder is not taken
status=0
(cd "$work" && "$bin" render sim --out "$work/photo" --zeta zeta-photo.json --count 1 --samples 1 --threads 1 \
  >out.txt 2>&1) || status=$?
[ "$status" -ne 0 ] && [ "$status" -lt 128 ] && grep -q -- "pass --backgrounds DIR" "$work/out.txt" ||
  fail "a --zeta naming its photo by file name without --backgrounds was not refused naming it: $(cat "$work/out.txt")"
# With --backgrounds (relative) it renders, and the zeta.json it writes renders the same photo again
# from another folder without it (a relative photo path in it was refused, or looked up twice).
(cd "$work" && "$bin" render sim --out photo --zeta zeta-photo.json --backgrounds . --count 1 --samples 1 \
  --threads 1 >out.txt 2>&1) || fail "render --zeta with --backgrounds .: $(cat "$work/out.txt")"
grep -q "\"background_image\": \"$work/sky.png\"" "$work/photo/zeta.json" ||
  fail "the written zeta.json does not name the photo by its absolute path: $(grep background_image "$work/photo/zeta.json")"
(cd / && "$bin" render "$work/sim" --out "$work/photo2" --zeta "$work/photo/zeta.json" --count 1 --samples 1 \
  --threads 1 >"$work/out.txt" 2>&1) || fail "render of render's own zeta.json: $(cat "$work/out.txt")"
cmp -s "$work/photo/000.jpg" "$work/photo2/000.jpg" || fail "render's own zeta.json rendered another image"
# A floating-point option given nan is refused as not finite; a name that reads as a number is
# a name (the finite-number check held every option: `--out inf` was "expected a finite number").
status=0
"$bin" render "$work/sim" --out "$work/fr" --fps nan >"$work/out.txt" 2>&1 || status=$?
[ "$status" -ne 0 ] && grep -q -- "--fps: expected a finite number" "$work/out.txt" ||
  fail "render --fps nan was not refused as not finite: $(cat "$work/out.txt")"
(cd "$work" && "$bin" render sim --out inf --count 1 --samples 1 --threads 1 >out.txt 2>&1) ||
  fail "render --out inf was refused: $(cat "$work/out.txt")"
[ -f "$work/inf/000.jpg" ] || fail "render --out inf wrote no frame"
# A killed run's temporaries (of a pid no process has) go with a rerun; they stayed for ever.
echo x >"$work/inf/000.jpg.tmp-999999999-3"
echo x >"$work/inf/zeta.json.tmp-999999999-4"
(cd "$work" && "$bin" render sim --out inf --count 1 --samples 1 --threads 1 >out.txt 2>&1) ||
  fail "render --out inf again: $(cat "$work/out.txt")"
left="$(cd "$work/inf" && LC_ALL=C ls)"
[ "$left" = "$(printf '000.jpg\nzeta.json')" ] || fail "a rerun left a killed run's temporaries: $left"
# --format jpeg is jpg, as make-dataset takes it (it was refused); --jpeg-quality beside png is
# refused (it was accepted and ignored).
(cd "$work" && "$bin" render sim --out jpeg --format jpeg --count 1 --samples 1 --threads 1 >out.txt 2>&1) ||
  fail "render --format jpeg was refused: $(cat "$work/out.txt")"
[ -f "$work/jpeg/000.jpg" ] || fail "render --format jpeg wrote no 000.jpg: $(ls "$work/jpeg")"
status=0
"$bin" render "$work/sim" --out "$work/q" --format png --jpeg-quality 50 --count 1 >"$work/out.txt" 2>&1 || status=$?
[ "$status" -ne 0 ] && [ "$status" -lt 128 ] && grep -q -- "--jpeg-quality is for JPEG" "$work/out.txt" ||
  fail "render --format png --jpeg-quality 50 was not refused naming --jpeg-quality: $(cat "$work/out.txt")"

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
# A cloth of another size than zeta's (a custom scene: here the flag scaled to 6 m x 4 m) flew
# beside its 3 m pole with the camera aimed past it, silently. With --seed zeta takes the cloth's
# size; a --zeta made for a 3 m flag is refused naming mesh_width, before --out is made.
mkdir "$work/big"
/usr/bin/python3 - "$work/sim/trajectory.cwtraj" "$work/big/trajectory.cwtraj" <<'PY'
import struct, sys
data = bytearray(open(sys.argv[1], 'rb').read())
nv, nf, frames = struct.unpack_from('<III', data, 12)
start = 32 + 12 * nf  # uv (material metres), then every frame's positions: all floats, all x2
for i in range(2 * nv + 3 * nv * frames):
    (x,) = struct.unpack_from('<f', data, start + 4 * i)
    struct.pack_into('<f', data, start + 4 * i, 2 * x)
open(sys.argv[2], 'wb').write(data)
PY
"$bin" render "$work/big" --out "$work/big-seed" --count 1 --samples 1 --threads 1 >"$work/out.txt" 2>&1 ||
  fail "a 6 m flag with --seed did not render: $(cat "$work/out.txt")"
grep -q "mesh_width" "$work/out.txt" || fail "render did not say it fitted zeta to the cloth: $(cat "$work/out.txt")"
/usr/bin/python3 - "$work/big-seed/zeta.json" <<'PY' || fail "zeta.json of the 6 m flag: $(cat "$work/big-seed/zeta.json")"
import json, sys
z = json.load(open(sys.argv[1]))
assert abs(z["mesh_width"] - 6) < 0.1 and abs(z["mesh_width"] / z["mesh_aspect_ratio"] - 4) < 0.1, z
PY
grep -q '"mesh_width": 3.0' "$work/zeta-3m.json" || fail "the 3 m flag's zeta changed: $(cat "$work/zeta-3m.json")"
status=0
"$bin" render "$work/big" --out "$work/big-zeta" --zeta "$work/zeta-3m.json" --count 1 --samples 1 --threads 1 \
  >"$work/out.txt" 2>&1 || status=$?
[ "$status" -ne 0 ] && [ "$status" -lt 128 ] || fail "a 3 m zeta rendered a 6 m flag (status $status): $(cat "$work/out.txt")"
grep -q "mesh_width" "$work/out.txt" || fail "the refusal does not name mesh_width: $(cat "$work/out.txt")"
[ ! -e "$work/big-zeta" ] || fail "the refused render made its --out"
# --keep-zeta renders a label's zeta as given (a dataset made with another scene), and says so.
"$bin" render "$work/big" --out "$work/big-keep" --zeta "$work/zeta-3m.json" --keep-zeta --count 1 --samples 1 \
  --threads 1 >"$work/out.txt" 2>&1 || fail "--keep-zeta did not render: $(cat "$work/out.txt")"
grep -q "keep-zeta: field 'mesh_width'" "$work/out.txt" || fail "--keep-zeta did not say what differs: $(cat "$work/out.txt")"
grep -q '"mesh_width": 3.0' "$work/big-keep/zeta.json" || fail "--keep-zeta changed zeta: $(cat "$work/big-keep/zeta.json")"
# The size is the cloth's rest size (its material space), not its first frame's: a flag flying
# stretched after a warm-up (here its 3 m flag's positions stretched by 10 %, its material space
# left) measured 3.3 m, and --seed rewrote zeta's size.
mkdir "$work/stretched"
/usr/bin/python3 - "$work/sim/trajectory.cwtraj" "$work/stretched/trajectory.cwtraj" <<'PY'
import struct, sys
data = bytearray(open(sys.argv[1], 'rb').read())
nv, nf, frames = struct.unpack_from('<III', data, 12)
start = 32 + 12 * nf + 8 * nv  # past the uv: every frame's positions
for i in range(3 * nv * frames):
    (x,) = struct.unpack_from('<f', data, start + 4 * i)
    struct.pack_into('<f', data, start + 4 * i, 1.1 * x)
open(sys.argv[2], 'wb').write(data)
PY
"$bin" render "$work/stretched" --out "$work/stretched-seed" --count 1 --samples 1 --threads 1 >"$work/out.txt" 2>&1 ||
  fail "the stretched flag did not render: $(cat "$work/out.txt")"
! grep -q "mesh_width" "$work/out.txt" || fail "a stretched 3 m flag changed zeta's size: $(cat "$work/out.txt")"
grep -q '"mesh_width": 3.0' "$work/stretched-seed/zeta.json" || fail "zeta of the stretched flag: $(cat "$work/stretched-seed/zeta.json")"
# A key zeta does not have (misspelt) is named in a warning; it was ignored without a word.
sed '0,/{/s//{"camera_hieght": 2.0,/' "$work/zeta-3m.json" >"$work/zeta-typo.json"
"$bin" render "$work/sim" --out "$work/typo" --zeta "$work/zeta-typo.json" --keep-zeta --count 1 --samples 1 --threads 1 \
  >"$work/out.txt" 2>&1 || true
grep -q "key 'camera_hieght' is not a render parameter (did you mean camera_height?) (ignored)" "$work/out.txt" ||
  fail "a misspelt zeta key was not named: $(cat "$work/out.txt")"
# Misspelt alone, the key is missing: the refusal names the misspelling too.
sed 's/"camera_height"/"camera_hieght"/' "$work/zeta-3m.json" >"$work/zeta-typo2.json"
status=0
"$bin" render "$work/sim" --out "$work/typo2" --zeta "$work/zeta-typo2.json" --keep-zeta --count 1 --samples 1 --threads 1 \
  >"$work/out.txt" 2>&1 || status=$?
[ "$status" -ne 0 ] && grep -q "missing field 'camera_height'; key 'camera_hieght' is not a render parameter (did you mean camera_height?)" "$work/out.txt" ||
  fail "a misspelt zeta key alone (status $status): $(cat "$work/out.txt")"
# Inputs that are not what they are named, and values out of range inside an input: each error
# names the input. A folder named as a trajectory or an OBJ frame read as empty ("truncated
# header", "no vertices"), a pipe was "no such file or folder", a background photo's path naming a
# folder "no such file", and a frame beyond the renderer's range or texture coordinates spanning
# 2 km named no file.
expect_refused() {  # expect_refused MESSAGE ARGS...: render ARGS fails (status 1, or 2 when MESSAGE
                   # names an option: the command line) saying MESSAGE
  local says="$1" status=0 expected=1
  shift
  [ "${says#--}" = "$says" ] || expected=2
  "$bin" render "$@" --count 1 --samples 1 --threads 1 >"$work/out.txt" 2>&1 || status=$?
  [ "$status" -eq "$expected" ] && grep -qF -- "$says" "$work/out.txt" ||
    fail "render $* (status $status) did not say '$says': $(cat "$work/out.txt")"
}
mkfifo "$work/pipe.cwtraj"
expect_refused "$work/pipe.cwtraj: not a file or folder (a pipe or a device)" "$work/pipe.cwtraj" --out "$work/bad"
mkdir -p "$work/dirtraj/trajectory.cwtraj" "$work/dirobj/0000_00.obj" "$work/pipetraj" "$work/pipeobj"
# A pipe inside a simulation folder waited for a writer for ever.
mkfifo "$work/pipetraj/trajectory.cwtraj" "$work/pipeobj/0000_00.obj"
expect_refused "$work/pipetraj/trajectory.cwtraj: not a regular file (a pipe or a device)" "$work/pipetraj" --out "$work/bad"
expect_refused "$work/pipeobj/0000_00.obj: not a regular file (a pipe or a device)" "$work/pipeobj" --out "$work/bad"
expect_refused "$work/dirtraj/trajectory.cwtraj: a folder, expected a trajectory file" "$work/dirtraj" --out "$work/bad"
expect_refused "$work/dirobj/0000_00.obj: a folder, expected an OBJ file" "$work/dirobj" --out "$work/bad"
square() {  # square FOLDER FAR_X FAR_U: a two-face OBJ frame, its far corners at x and u as given
  mkdir -p "$1"
  printf 'v 0 0 0\nv %s 0 0\nv %s 1 0\nv 0 1 0\nvt 0 0\nvt %s 0\nvt %s 1\nvt 0 1\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n' \
    "$2" "$2" "$3" "$3" >"$1/0000_00.obj"
}
square "$work/far" 2e6 1
expect_refused "OBJ frames in $work/far, frame at 0 s: SetCloth: vertex 1 has V coordinate x = 2e+06" \
  "$work/far" --out "$work/bad"
square "$work/wide" 1 2000
expect_refused "OBJ frames in $work/wide: render params: field 'mesh_width'" "$work/wide" --out "$work/bad"
square "$work/ok" 1 1
"$bin" render "$work/ok" --out "$work/okr" --count 1 --samples 1 --threads 1 >/dev/null 2>&1 || fail "the square did not render"
sed 's#"background_image": *"[^"]*"#"background_image": "'"$work"'"#' "$work/okr/zeta.json" >"$work/zeta-folder.json"
grep -q "\"background_image\": \"$work\"" "$work/zeta-folder.json" || fail "no background_image to set in zeta.json"
expect_refused "background_image '$work': not a file (a folder, a pipe or a device)" "$work/ok" --out "$work/bad" \
  --zeta "$work/zeta-folder.json" --keep-zeta
# Rendering into a folder from its own zeta.json: refused, the file kept (the run removes it until
# its frames are whole, and a Ctrl-C lost it).
cp "$work/okr/zeta.json" "$work/okr-zeta-before.json"
expect_refused "--zeta $work/okr/zeta.json is --out's own zeta.json" "$work/ok" --out "$work/okr" --zeta "$work/okr/zeta.json"
cmp -s "$work/okr/zeta.json" "$work/okr-zeta-before.json" || fail "render from --out's own zeta.json changed it"
# A simulate folder without its summary.json (a run stopped while it wrote its OBJs): --obj is
# refused, the OBJs may stop short (they rendered 5 s of a 20 s run, exit 0).
"$bin" simulate "$src/config/scenes/flag.json" --out "$work/killed" --duration 0.08 --max-edge 1 >/dev/null 2>&1
rm "$work/killed/summary.json" "$work/killed/0002_00.obj"
expect_refused "simulate did not finish there (no summary.json)" "$work/killed" --obj --out "$work/bad"
echo "render_cli_test: OK"
