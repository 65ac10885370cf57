#!/usr/bin/env bash
# Builds the libFuzzer targets (tests/fuzz, GINS_FUZZ=ON, Debian clang + ASan + UBSan) in build-fuzz/ and runs
# each for a bounded time: scripts/fuzz.sh [seconds per target, default 120] [target ...].
# Seeds: tests/fuzz/corpus/<target>/ (in the repository; the config fuzzer also starts from config/*.yaml; the
# stream fuzzer's are slices of data/sample/log.txt.gz made by build-fuzz/tests/fuzz/make_stream_seeds).
# New inputs that reach new code go to build-fuzz/corpus/<target>/ (not the repository); a crash leaves
# build-fuzz/crash-<target>-* and makes the script fail.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-120}"
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(log_line log_reader config stream export_source gnss_formats rinex)

if ! command -v clang++ >/dev/null || ! ls /usr/lib/llvm-*/lib/clang/*/lib/linux/libclang_rt.fuzzer-x86_64.a >/dev/null 2>&1; then
  echo "gins fuzz: installing clang and libclang-rt-14-dev"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends clang libclang-rt-14-dev >/dev/null
fi
./scripts/install_deps.sh
cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ -DGINS_FUZZ=ON \
  -DGINS_BUILD_TESTS=OFF >/dev/null
cmake --build build-fuzz -j"$(nproc)" --target $(printf '%s_fuzzer ' "${targets[@]}")

status=0
for t in "${targets[@]}"; do
  corpus=build-fuzz/corpus/$t
  mkdir -p "$corpus"
  seeds=(tests/fuzz/corpus/$t)
  [ "$t" = config ] && seeds+=(config)
  echo "gins fuzz: $t for ${seconds} s"
  # -rss_limit_mb: the reader's memory is bounded; -timeout: no input may take two seconds, a hang's mark. The
  # stream target runs both estimators on up to 3000 records, and an ill-conditioned window takes the dense
  # eigen-decomposition of its covariance at every keyframe (solver/smoother_output.cc): its corpus input
  # finding_slow_ill_conditioned_window takes 8-9 s in this ASan + coverage build (under 0.5 s in Release,
  # where StreamCorpus replays it), so that target gets 30 s.
  timeout=2
  [ "$t" = stream ] && timeout=30
  if ! build-fuzz/tests/fuzz/${t}_fuzzer "$corpus" "${seeds[@]}" -max_total_time="$seconds" -timeout="$timeout" \
      -rss_limit_mb=2048 -max_len=4096 -artifact_prefix="build-fuzz/crash-$t-" -print_final_stats=1 \
      >"build-fuzz/$t.log" 2>&1; then
    echo "gins fuzz: $t FAILED (see build-fuzz/$t.log and build-fuzz/crash-$t-*)"
    status=1
  fi
  grep -E "^stat::number_of_executed_units|^stat::new_units_added|^Done" "build-fuzz/$t.log" || true
done
exit $status
