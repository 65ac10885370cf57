// libFuzzer target: the estimators on an arbitrary stream of well-formed records. The bytes decode into run
// options and records the log reader could have produced (tests/fuzz/stream_format.h: IMU, ODOM, GNSS with
// and without heading and σ, GVEL; time steps, gaps, jumps, bursts of one stamp, rate changes, jitter, and a
// consistent vehicle with sensor faults), which go through a EstimatorPipeline with the ESKF and the smoother (small
// window, few iterations) as `gins run` feeds them. The invariants are stream_harness.h's: no abort or
// unexpected exception, finite states and σ, σ > 0 where written, time order. A violation aborts with its
// description; scripts/fuzz.sh runs it as `stream`, seeds in corpus/stream/ (make_stream_seeds.cc).
#include <glog/logging.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include "fuzz/stream_harness.h"

extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  FLAGS_minloglevel = google::GLOG_ERROR;  // the watchdog's warnings would drown the fuzzer's output
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const gins::fuzz::StreamResult r = gins::fuzz::RunStream(data, size);
  if (!r.failure.empty()) {
    std::fprintf(stderr, "stream invariant violated (%zu records): %s\n", r.records, r.failure.c_str());
    std::abort();
  }
  return 0;
}
