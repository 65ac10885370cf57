#!/usr/bin/env bash
# Configures and builds gins (Release) into build/. `--target NAME` (repeatable, first) builds only those
# targets (the quick start builds `gins`, not the tests); the other arguments go to CMake's configure step.
# The Python package (docs/python.md) is built too whenever CMake builds it (GINS_BUILD_PYTHON, on with
# pybind11), and made importable by Debian's python3: a .pth file in its site-packages (as root) names the
# build's package folder, so `/usr/bin/python3 -c "import gins"` gets this build.
set -euo pipefail
cd "$(dirname "$0")/.."
targets=()
while [ $# -ge 2 ] && [ "$1" = "--target" ]; do
  targets+=(--target "$2")
  shift 2
done
# Ninja where the build folder is new (it starts a library's objects before the libraries below it are
# linked: fewer idle cores); a folder configured before keeps its generator.
generator=()
[ -f build/CMakeCache.txt ] || ! command -v ninja >/dev/null || generator=(-G Ninja)
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release "${generator[@]}" "$@" >/dev/null
python=0
grep -q '^GINS_BUILD_PYTHON:BOOL=ON' build/CMakeCache.txt && python=1
if [ ${#targets[@]} -gt 0 ] && [ $python = 1 ]; then targets+=(--target gins_python); fi
cmake --build build -j"$(nproc)" "${targets[@]}"
if [ $python = 1 ]; then
  package="$PWD/build/apps/python/package"
  site=$(/usr/bin/python3 -c 'import site; print(site.getsitepackages()[0])')
  if ! { mkdir -p "$site" && echo "$package" > "$site/gins.pth"; } 2>/dev/null; then
    echo "gins: cannot write $site/gins.pth; for the Python package: export PYTHONPATH=$package" >&2
  fi
fi
