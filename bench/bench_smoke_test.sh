#!/usr/bin/env bash
# Every bench program runs on its quickest settings and prints its table, and refuses a bad
# number naming the option with status 1 (no SIGABRT): a bench that broke left `make test` green,
# and benches ended with "terminate called ... stod". The figures are not checked: speed is read
# by hand from Release builds (docs), not asserted in tests; a bench built otherwise says so.
# Usage: bench_smoke_test.sh BIN_DIR [BUILD_TYPE]
set -euo pipefail
bin="$1"
build_type="${2:-Release}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
fail() { echo "bench_smoke_test: FAIL: $*" >&2; exit 1; }
cd "$work"  # any folder: the benches find the source tree's scenes themselves

runs() {  # runs EXPECTED_TEXT BENCH ARGS...: exits 0 and prints the text
  local text="$1" name="$2"
  shift 2
  [ -x "$bin/$name" ] || { echo "bench_smoke_test: $name not built (skipped)"; return 0; }
  "$bin/$name" "$@" >out.txt 2>&1 || fail "$name $*: status $?: $(tail -5 out.txt)"
  grep -qF -- "$text" out.txt || fail "$name $*: no '$text' in its output: $(tail -5 out.txt)"
  if [ "$build_type" = Release ]; then
    ! grep -q "not Release" out.txt || fail "$name (a Release build) says it is not one: $(grep 'not Release' out.txt)"
  else
    grep -qF "built as '$build_type', not Release" out.txt || fail "$name (built as '$build_type') does not say so"
  fi
}
refuses() {  # refuses OPTION BENCH ARGS...: status 1 (not a signal), the message names OPTION
  local option="$1" name="$2" status=0
  shift 2
  [ -x "$bin/$name" ] || return 0
  "$bin/$name" "$@" >out.txt 2>&1 || status=$?
  [ "$status" -eq 1 ] || fail "$name $*: status $status, expected 1: $(tail -3 out.txt)"
  grep -qF -- "$option" out.txt || fail "$name $*: the message does not name $option: $(tail -3 out.txt)"
}

runs "| 3 |" sim_bench --duration 0.4 --winds 3
runs "fine_offset" anemometer_decode_bench 2000
runs "GREY" camera_convert_bench 1
runs "ms/clip" sensors_clip_bench
runs "60-frame clip" render_bench --frames 2 --samples 1
runs "clips/min" dataset_bench --count 1 --views 1 --max-edge 0.5 --samples 1
runs "mean [ms]" sdn_bench --quick --repeats 1
runs "128" learn_train_step_bench --repeats 1 --batch 2 --width 8
runs "BM_MotionMapOnly" learn_fly_judge_bench --benchmark_min_time=0.01

# Counts read with atoi ran on: "--repeats x" ran once, "--frames 2.9" two frames.
refuses "--count: expected a finite number" dataset_bench --count x
refuses "--max-edge: expected a finite number" dataset_bench --max-edge 0.5m
refuses "--repeats: expected a finite number" learn_train_step_bench --repeats x
refuses "--frames: expected a whole number" render_bench --frames 2.9
refuses "--seed: expected a whole number >= 0" render_bench --seed -1
refuses "--repeats: expected a finite number" sdn_bench --repeats x
refuses "--duration: expected a finite number" sim_bench --duration x
refuses "--winds" sim_bench --winds ,
refuses "--duration" sim_bench --duration 0.2 --winds 3
refuses "--model /nonexistent.pt" sdn_bench --model /nonexistent.pt
# The benches with a positional count read "--help" with atoi as 0 and ran: help is printed, and a
# count that is not one is refused naming it.
runs "Usage: anemometer_decode_bench" anemometer_decode_bench --help
runs "Usage: camera_convert_bench" camera_convert_bench -h
runs "Usage: sensors_clip_bench" sensors_clip_bench --help
refuses "records per protocol" anemometer_decode_bench x
refuses "repetitions" camera_convert_bench 0
refuses "takes no arguments" sensors_clip_bench 5
echo "bench_smoke_test: OK"
