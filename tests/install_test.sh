#!/usr/bin/env bash
# The install space works on its own: `cmake --install` into a fresh prefix, then every installed
# program starts without LD_LIBRARY_PATH or the source tree's variables (the core's shared
# libraries used to stay in the build tree), and the installed CLI reads the installed scenes,
# not the source tree it was built from (a scene broken in the install only must be the one that
# fails, by its installed path). Usage: install_test.sh BUILD_DIR
set -euo pipefail
build="$1"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
fail() { echo "install_test: FAIL: $*" >&2; exit 1; }

cmake --install "$build" --prefix "$work/prefix" >/dev/null
# Moved after installing: nothing may point back at where it was installed.
mv "$work/prefix" "$work/moved"
prefix="$work/moved"
clean_env=(env -u LD_LIBRARY_PATH -u CLOTHWIND_SOURCE_DIR -u CLOTHWIND_SHARED_DIR)

programs=("$prefix/bin/clothwind" "$prefix"/lib/clothwind/*_node)
[ "${#programs[@]}" -ge 7 ] || fail "expected the CLI and six nodes, found: ${programs[*]}"
for p in "${programs[@]}"; do
  [ -x "$p" ] || fail "$p is not installed"
  missing="$("${clean_env[@]}" ldd "$p" | grep 'not found' || true)"
  [ -z "$missing" ] || fail "$p lacks libraries: $missing"
done
"${clean_env[@]}" "$prefix/bin/clothwind" --help >/dev/null || fail "the installed CLI does not start"
for f in share/clothwind/config/scenes/flag.json share/clothwind/models/sdn.pt share/clothwind/launch/replay.launch \
    share/clothwind/scripts/replay-player; do
  [ -f "$prefix/$f" ] || fail "$f is not installed"
done
[ -x "$prefix/share/clothwind/scripts/replay-player" ] || fail "the installed replay-player is not executable"

echo '{ "frame_time": ' > "$prefix/share/clothwind/config/scenes/flag.json"
status=0
(cd "$work" && "${clean_env[@]}" "$prefix/bin/clothwind" make-dataset --kind flag --count 1 --views 1 \
  --size 16 --frames 2 --jobs 1 --out "$work/ds") >"$work/out.txt" 2>&1 || status=$?
[ "$status" -ne 0 ] || fail "make-dataset read a scene other than the broken installed one: $(cat "$work/out.txt")"
grep -q "$prefix/share/clothwind/config/scenes/flag.json" "$work/out.txt" ||
  fail "the error does not name the installed scene: $(cat "$work/out.txt")"
echo "install_test: OK (${#programs[@]} programs from a moved prefix)"
