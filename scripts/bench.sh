#!/usr/bin/env bash
# Builds gins (Release) with the Google Benchmark micro-benchmarks and runs them. Extra arguments go to
# the benchmark binary (e.g. --benchmark_filter=Eskf --benchmark_repetitions=5).
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install_deps.sh libbenchmark-dev
cmake -S . -B build-bench -DCMAKE_BUILD_TYPE=Release -DGINS_BUILD_TESTS=OFF -DGINS_BUILD_BENCHMARKS=ON >/dev/null
cmake --build build-bench --target gins_bench -j"$(nproc)"
./build-bench/tests/bench/gins_bench "$@"
