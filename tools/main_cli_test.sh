#!/usr/bin/env bash
# CLI test of `clothwind` itself: a mistyped verb is named with the verb it was likely meant to be
# (it was told only "A subcommand is required"), an unknown word is named, status 2 for both;
# unsigned options are refused beyond 0..2^64-1 (and ranges said readably); --version prints
# package.xml's version.
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
out="$("$bin" train --epochs -3 --data "$work" --out "$work/run" 2>&1)" || true
grep -q -- "--epochs: Value -3 must be > 0$" <<<"$out" || fail "--epochs -3: $out"
"$bin" make-toy-dataset --seed 18446744073709551615 --clips 1 --frames 2 --size 16 --out "$work/toy" >/dev/null 2>&1 ||
  fail "make-toy-dataset --seed 2^64-1 was refused"
version="$(sed -n 's:.*<version>\(.*\)</version>.*:\1:p' "$src/package.xml")"
[ "$("$bin" --version)" = "clothwind $version" ] || fail "--version: $("$bin" --version 2>&1)"
echo "main_cli_test: OK"
