#!/usr/bin/env bash
# CLI test of `clothwind` itself: a mistyped verb is named with the verb it was likely meant to be
# (it was told only "A subcommand is required"), an unknown word is named, status 2 for both;
# --version prints package.xml's version.
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
version="$(sed -n 's:.*<version>\(.*\)</version>.*:\1:p' "$src/package.xml")"
[ "$("$bin" --version)" = "clothwind $version" ] || fail "--version: $("$bin" --version 2>&1)"
echo "main_cli_test: OK"
