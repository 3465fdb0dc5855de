#!/usr/bin/env bash
# CLI test of `clothwind export-model --calibrate-std`: a dataset without a val split (which the
# calibration reads) is refused before any work, naming the option and the way out; one with a
# val split is calibrated and its scale stored beside the exported weights.
# Usage: export_model_cli_test.sh CLOTHWIND_BINARY
set -euo pipefail
bin="$1"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
fail() { echo "export_model_cli_test: FAIL: $*" >&2; exit 1; }

"$bin" make-toy-dataset --out "$work/toy" --clips 16 --frames 30 --size 32 >"$work/msg.txt" 2>&1 ||
  fail "make-toy-dataset: $(cat "$work/msg.txt")"
grep -q '"split": "val"' "$work/toy/index.json" || fail "the toy dataset drew no val clip: $(cat "$work/toy/index.json")"
"$bin" train --model sdn --frames 30 --data "$work/toy" --out "$work/run" --input-size 32 --width 8 --k 3 \
  --threads 1 --init-only >"$work/msg.txt" 2>&1 || fail "train --init-only: $(cat "$work/msg.txt")"

# The same clips with the val split moved to train.
cp -r "$work/toy" "$work/noval"
sed -i 's/"split": "val"/"split": "train"/' "$work/noval/index.json" "$work"/noval/*/label.json
status=0
"$bin" export-model --model "$work/run/model.pt" --out "$work/noval-export/sdn.pt" --calibrate-std "$work/noval" \
  --threads 1 >"$work/msg.txt" 2>&1 || status=$?
[ "$status" -ne 0 ] && [ "$status" -lt 128 ] || fail "no val split: exited $status: $(cat "$work/msg.txt")"
grep -q -- "--calibrate-std $work/noval: the dataset has no val split" "$work/msg.txt" &&
  grep -q "leave --calibrate-std out" "$work/msg.txt" ||
  fail "no val split: the message does not name the option and the way out: $(cat "$work/msg.txt")"
[ ! -e "$work/noval-export/sdn.pt" ] || fail "no val split: an export was written"

"$bin" export-model --model "$work/run/model.pt" --out "$work/export/sdn.pt" --calibrate-std "$work/toy" \
  --threads 1 >"$work/msg.txt" 2>&1 || fail "with a val split: $(cat "$work/msg.txt")"
grep -q "std calibration on" "$work/msg.txt" || fail "with a val split: no calibration said: $(cat "$work/msg.txt")"
grep -q '"std_scale"' "$work/export/sdn.json" || fail "no std_scale in $(cat "$work/export/sdn.json")"
echo "export_model_cli_test: OK"
