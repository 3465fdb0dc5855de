#!/usr/bin/env bash
# CLI test of `clothwind` itself: a mistyped verb is named with the verb it was likely meant to be
# (it was told only "A subcommand is required"), an unknown word is named, status 2 for both;
# unsigned options are refused beyond 0..2^64-1 (and ranges said readably); --version prints
# package.xml's version; signed whole-number options read decimal too, words and non-finite numbers
# are named as such; and the exit statuses: 2 for any wrong command line (CLI11's own errors and
# the verbs' checks alike), 1 for work that failed, 0 for --help.
# Usage: main_cli_test.sh CLOTHWIND_BINARY SOURCE_DIR
set -euo pipefail
bin="$1"
src="$2"
fail() { echo "main_cli_test: FAIL: $*" >&2; exit 1; }
status=0
out="$("$bin" make-datset --count 1 2>&1)" || status=$?
[ "$status" -eq 2 ] && [ "$out" = "clothwind: unknown verb 'make-datset'; did you mean make-dataset? (clothwind --help lists the verbs)" ] ||
  fail "a mistyped verb (status $status): $out"
status=0
out="$("$bin" frobnicate 2>&1)" || status=$?
[ "$status" -eq 2 ] && [ "$out" = "clothwind: unknown verb 'frobnicate' (clothwind --help lists the verbs)" ] ||
  fail "an unknown verb (status $status): $out"
# Unsigned options take 0..2^64-1 in digits: -1 wrapped to 2^64-1 and 2^64 was clamped to it, both
# without a word; unbounded ranges are said as a bound, not as 309 digits of the largest double.
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
for seed in -1 18446744073709551616 1e3; do
  status=0
  out="$("$bin" make-toy-dataset --seed "$seed" --out "$work/toy" 2>&1)" || status=$?
  [ "$status" -ne 0 ] && [ ! -e "$work/toy" ] && grep -q -- "--seed: .*$seed" <<<"$out" ||
    fail "make-toy-dataset --seed $seed was not refused naming it (status $status): $out"
done
# Decimal as written: CLI11 read 010 as C's octal 8.
"$bin" make-toy-dataset --seed 010 --clips 1 --frames 2 --size 16 --out "$work/s010" >/dev/null 2>&1
"$bin" make-toy-dataset --seed 8 --clips 1 --frames 2 --size 16 --out "$work/s8" >/dev/null 2>&1
"$bin" make-toy-dataset --seed 10 --clips 1 --frames 2 --size 16 --out "$work/s10" >/dev/null 2>&1
cmp -s "$work/s010/index.json" "$work/s10/index.json" && ! cmp -s "$work/s010/index.json" "$work/s8/index.json" ||
  fail "--seed 010 is not seed 10"
# Signed whole numbers likewise: --clips 010 wrote 8 examples and 0x10 16.
"$bin" make-toy-dataset --clips 010 --frames 2 --size 16 --out "$work/c010" >/dev/null 2>&1
[ "$(/usr/bin/python3 -c 'import json, sys; print(len(json.load(open(sys.argv[1]))["clips"]))' "$work/c010/index.json")" = 10 ] ||
  fail "--clips 010 did not write 10 examples"
expect_usage() {  # expect_usage MESSAGE_PATTERN ARGS...: status 2, the message on stderr
  local pattern="$1" status=0 out
  shift
  out="$("$bin" "$@" 2>&1 >/dev/null)" || status=$?
  [ "$status" -eq 2 ] && grep -q -- "$pattern" <<<"$out" || fail "$* (status $status, expected 2 and '$pattern'): $out"
}
expect_usage "--clips: expected a whole number, got 0x10" make-toy-dataset --clips 0x10 --out "$work/x"
expect_usage "--clips: expected a whole number, got abc" make-toy-dataset --clips abc --out "$work/x"
expect_usage "--size: expected a whole number, got 1e3" make-toy-dataset --size 1e3 --out "$work/x"
expect_usage "--lr: expected a finite number, got inf" train --lr inf --data "$work" --out "$work/run"
expect_usage "--lr: expected a finite number, got 1e400" train --lr 1e400 --data "$work" --out "$work/run"
expect_usage "--lr: expected a number, got fast" train --lr fast --data "$work" --out "$work/run"
expect_usage "--model is required" eval                                  # CLI11's own (was 106)
expect_usage "a verb is required" # no verb: the verbs listed (was 106, "A subcommand is required")
{ "$bin" 2>&1 || true; } | grep -q "^  make-dataset " || fail "clothwind with no verb does not list the verbs"
expect_usage "--warmup must be in 0..3600 s" simulate "$src/config/scenes/flag.json" --out "$work/sim" --warmup -1
[ ! -e "$work/x" ] && [ ! -e "$work/sim" ] || fail "a refused command line wrote something"
# An --out no file can be made in is named as the option, before any work (it was "filesystem
# error: cannot create directories: ... [/proc/x]"); render's --cloth is two digits.
for verb in "make-toy-dataset" "make-dataset --count 1" "simulate $src/config/scenes/flag.json" "train --data $work" \
            "render $work"; do
  # shellcheck disable=SC2086
  expect_usage "--out /proc/clothwind-x: cannot write in /proc" $verb --out /proc/clothwind-x
done
expect_usage "--cloth: Value -1 not in range 0 to 99" render "$work" --out "$work/r" --cloth -1
expect_usage "--max-edge must be a finite length" simulate "$src/config/scenes/flag.json" --out "$work/sim" --max-edge -1
# Work that failed is 1: a scene that is not JSON.
echo "{" >"$work/bad.json"
status=0
out="$("$bin" simulate "$work/bad.json" --out "$work/sim" 2>&1)" || status=$?
[ "$status" -eq 1 ] && grep -q "bad.json" <<<"$out" || fail "a scene that is not JSON (status $status): $out"
# So is an input that is not there, for every verb (simulate and bag-check said 2, as CLI11 checked
# the file before the verb ran; eval, train and the rest 1).
for verb in "simulate $work/none.json --out $work/sim" "bag-check $work/none.bag" \
            "eval --model $work/none.pt --data $work" "train --data $work/none --out $work/run"; do
  status=0
  # shellcheck disable=SC2086
  out="$("$bin" $verb 2>&1)" || status=$?
  [ "$status" -eq 1 ] && grep -q "$work/none" <<<"$out" || fail "$verb: a missing input (status $status): $out"
done
"$bin" simulate --help >/dev/null || fail "simulate --help did not exit 0"
out="$("$bin" train --epochs -3 --data "$work" --out "$work/run" 2>&1)" || true
grep -q -- "--epochs: Value -3 must be > 0$" <<<"$out" || fail "--epochs -3: $out"
"$bin" make-toy-dataset --seed 18446744073709551615 --clips 1 --frames 2 --size 16 --out "$work/toy" >/dev/null 2>&1 ||
  fail "make-toy-dataset --seed 2^64-1 was refused"
# A trailing comma is no number (--wind 1,2,3, was read as 1,2,3).
status=0
out="$("$bin" simulate "$src/config/scenes/flag.json" --out "$work/sim" --wind 1,2,3, 2>&1)" || status=$?
[ "$status" -eq 2 ] && grep -qF -- "--wind: expected 3 comma-separated numbers, got '1,2,3,'" <<<"$out" ||
  fail "--wind 1,2,3,: not refused (status $status): $out"
# An empty value is refused as a command line naming the option (eval --json "" ran without
# writing JSON; make-toy-dataset --out "" failed with "cannot create directories: Invalid argument").
for verb in "make-toy-dataset --clips 1 --frames 2 --size 16 --out|--out" "eval --model $work/m.pt --data $work --json|--json" \
            "contact-sheet|dir"; do
  args="${verb%%|*}" named="${verb#*|}"
  status=0
  # shellcheck disable=SC2086
  out="$("$bin" $args "" 2>&1)" || status=$?
  [ "$status" -eq 2 ] && grep -qF -- "$named: an empty value" <<<"$out" ||
    fail "$args \"\": not refused naming $named (status $status): $out"
done
version="$(sed -n 's:.*<version>\(.*\)</version>.*:\1:p' "$src/package.xml")"
[ "$("$bin" --version)" = "clothwind $version" ] || fail "--version: $("$bin" --version 2>&1)"
echo "main_cli_test: OK"
