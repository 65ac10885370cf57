#!/usr/bin/env bash
# The test suite under AddressSanitizer + UndefinedBehaviorSanitizer (build-asan/, -O1 -g1; UBSan on the
# library and app code, not the tests' own: CMakeLists.txt), all but the drives labelled `long`
# (tests/long_tests.cmake: minutes each under the sanitizers; their code runs there through the shorter
# drives). Any sanitizer report fails the run. CI runs it after scripts/test.sh.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install_deps.sh --test
# -O1 -g1 and no NDEBUG: faster to compile than -O2 -g, line numbers in reports, Eigen and glog checks on.
generator=()  # as scripts/build.sh
[ -f build-asan/CMakeCache.txt ] || ! command -v ninja >/dev/null || generator=(-G Ninja)
cmake -S . -B build-asan "${generator[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" \
  -DGINS_SANITIZE=ON >/dev/null
cmake --build build-asan -j"$(nproc)"
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
(cd build-asan && ctest --output-on-failure -j"$(nproc)" --label-exclude long)
