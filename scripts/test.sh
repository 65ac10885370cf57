#!/usr/bin/env bash
# The README's test command: install what is missing, build (Release, build/), run the whole test suite.
# CI (.ci/run) runs this, then scripts/test_sanitizers.sh (the same suite under ASan + UBSan).
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install_deps.sh --test
./scripts/build.sh
(cd build && ctest --output-on-failure -j"$(nproc)")
