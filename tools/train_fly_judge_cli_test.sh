#!/usr/bin/env bash
# CLI test of `clothwind train-fly-judge --measure`, which trains nothing: each training option
# beside it (accepted and ignored) is refused naming both, before the dataset is read; and a
# dataset of anything but FlagSim flags is refused.
# Usage: train_fly_judge_cli_test.sh CLOTHWIND_BINARY
set -euo pipefail
bin="$1"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
fail() { echo "train_fly_judge_cli_test: FAIL: $*" >&2; exit 1; }

for option in "--hidden 8" "--epochs 2" "--batch 4" "--lr 0.01" "--weight-decay 0" "--seed 2" "--shift 0"; do
  status=0
  # shellcheck disable=SC2086
  "$bin" train-fly-judge --data "$work/no_dataset" --measure "$work/judge.pt" $option >"$work/msg.txt" 2>&1 ||
    status=$?
  [ "$status" -ne 0 ] && [ "$status" -lt 128 ] || fail "--measure with $option exited $status: $(cat "$work/msg.txt")"
  grep -q -- "--measure excludes ${option%% *}" "$work/msg.txt" ||
    fail "--measure with $option: the message does not name both: $(cat "$work/msg.txt")"
done
# A dataset with no flag (toy stripes here; a hanging cloth too) trained a judge that scored 0 %, exit 0,
# and is refused for --measure as well.
"$bin" make-toy-dataset --out "$work/toy" --clips 4 --frames 30 --size 32 >/dev/null 2>&1
status=0
"$bin" train-fly-judge --data "$work/toy" --out "$work/judge/j.pt" >"$work/msg.txt" 2>&1 || status=$?
[ "$status" -ne 0 ] && [ "$status" -lt 128 ] && grep -q -- "is a \"toy\" dataset, with no flag; the fly judge is trained" "$work/msg.txt" &&
  [ ! -e "$work/judge/j.pt" ] || fail "train-fly-judge on a toy dataset (status $status): $(cat "$work/msg.txt")"
status=0
"$bin" train-fly-judge --data "$work/toy" --measure "$(dirname "$0")/../models/fly_judge.pt" >"$work/msg.txt" 2>&1 || status=$?
[ "$status" -ne 0 ] && [ "$status" -lt 128 ] && grep -q -- "with no flag" "$work/msg.txt" ||
  fail "train-fly-judge --measure on a toy dataset (status $status): $(cat "$work/msg.txt")"
# An existing judge is replaced only with --overwrite, checked before the training's minutes
# (train-fly-judge --out models/fly_judge.pt replaced the shipped judge without a word).
mkdir -p "$work/judges"
echo x >"$work/judges/j.json"
status=0
"$bin" train-fly-judge --data "$work/toy" --out "$work/judges/j.pt" >"$work/msg.txt" 2>&1 || status=$?
[ "$status" -eq 2 ] && grep -qF -- "--out: $work/judges/j.json exists; --overwrite replaces it" "$work/msg.txt" &&
  [ "$(cat "$work/judges/j.json")" = x ] ||
  fail "an existing judge's card without --overwrite (status $status): $(cat "$work/msg.txt")"
status=0
"$bin" train-fly-judge --data "$work/toy" --out "$work/judges/j.pt" --overwrite >"$work/msg.txt" 2>&1 || status=$?
grep -q "with no flag" "$work/msg.txt" || fail "--overwrite was not taken: $(cat "$work/msg.txt")"
# --overwrite replaces an earlier judge, never a clip's frame or label (a judge's weights went over
# a frame, its card over a label.json, exit 0).
cp "$work/toy/toy-00001/label.json" "$work/label-before.json"
for out in "$work/toy/toy-00001/003.jpg" "$work/toy/toy-00001/label.pt"; do
  status=0
  "$bin" train-fly-judge --data "$work/toy" --out "$out" --overwrite >"$work/msg.txt" 2>&1 || status=$?
  [ "$status" -eq 2 ] && grep -q "inside the example folder $work/toy/toy-00001" "$work/msg.txt" ||
    fail "train-fly-judge --out $out: not refused (status $status): $(cat "$work/msg.txt")"
  cmp -s "$work/toy/toy-00001/label.json" "$work/label-before.json" || fail "--out $out changed the clip's label"
done
echo "train_fly_judge_cli_test: OK"
