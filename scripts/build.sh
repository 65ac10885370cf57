#!/usr/bin/env bash
# Configures and builds gins (Release) into build/. `--target NAME` (repeatable, first) builds only those
# targets (the quick start builds `gins`, not the tests); the other arguments go to CMake's configure step.
set -euo pipefail
cd "$(dirname "$0")/.."
targets=()
while [ $# -ge 2 ] && [ "$1" = "--target" ]; do
  targets+=(--target "$2")
  shift 2
done
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release "$@" >/dev/null
cmake --build build -j"$(nproc)" "${targets[@]}"
