# Sourced by the tests' launch-prefix scripts: sets `cli` to the clothwind executable of the build
# under test, or exits with a message naming the caller. The CLI lands in <build>/bin; the build's
# devel space is on CMAKE_PREFIX_PATH.
cli=""
if [ -n "${CLOTHWIND_BUILD:-}" ] && [ -x "$CLOTHWIND_BUILD/bin/clothwind" ]; then
  cli="$CLOTHWIND_BUILD/bin/clothwind"
else
  IFS=: read -r -a prefixes <<< "${CMAKE_PREFIX_PATH:-}"
  for p in "${prefixes[@]}"; do
    if [ -x "$p/../bin/clothwind" ]; then cli="$p/../bin/clothwind"; break; fi
  done
fi
if [ -z "$cli" ]; then
  echo "$(basename "$0"): cannot find the clothwind executable (set CLOTHWIND_BUILD)" >&2
  exit 1
fi
