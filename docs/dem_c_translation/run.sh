#!/usr/bin/env bash
# The C translation of the DEM kernel against Numba on the four bench beds (README.md
# beside this file). Run from anywhere; takes ~40 s on 2 cores. Needs gcc (clang-14 too,
# if installed) and the project installed or on PYTHONPATH.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
export PYTHONPATH="$root:$here${PYTHONPATH:+:$PYTHONPATH}"
PY="${PYTHON:-python}"
build="$(mktemp -d)"
trap 'rm -rf "$build"' EXIT
"$PY" "$here/dump.py" 20000
strict="-O3 -march=native -ffp-contract=off -fPIC -shared"
gcc $strict -o "$build/gcc_O3.so" "$here/ckernel.c" -lm
gcc -O3 -march=native -ffast-math -fPIC -shared -o "$build/gcc_O3_fastmath.so" \
    "$here/ckernel.c" -lm
"$PY" "$here/run_c.py" "$build/gcc_O3.so" --repeat 3
"$PY" "$here/run_c.py" "$build/gcc_O3_fastmath.so" --repeat 3 --no-numba
if command -v clang-14 >/dev/null; then
    clang-14 $strict -fno-math-errno -o "$build/clang_O3.so" "$here/ckernel.c" -lm
    "$PY" "$here/run_c.py" "$build/clang_O3.so" --repeat 3 --no-numba
fi
