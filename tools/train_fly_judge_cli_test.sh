#!/usr/bin/env bash
# CLI test of `clothwind train-fly-judge --measure`, which trains nothing: each training option
# beside it (accepted and ignored) is refused naming both, before the dataset is read.
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
echo "train_fly_judge_cli_test: OK"
