// The stream fuzzer's corpus (tests/fuzz/corpus/stream/: slices of the bundled sample and the regressions of
// findings) replayed through the fuzzer's own harness (tests/fuzz/stream_harness.h) in every build, so the
// invariants hold in CI and under its sanitizers without clang or libFuzzer. GINS_STREAM_INPUT=FILE replays
// one file and says what it decoded (for a crash file of the fuzzer).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "fuzz/stream_harness.h"

namespace gins {
namespace GINS_TEST_FILE {

std::vector<uint8_t> ReadBytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void Replay(const std::filesystem::path& path) {
  const std::vector<uint8_t> bytes = ReadBytes(path);
  const fuzz::StreamResult r = fuzz::RunStream(bytes.data(), bytes.size());
  std::printf("%s: %zu bytes, %zu records, %s, %zu states\n", path.filename().c_str(), bytes.size(), r.records,
              r.initialized ? "initialised" : "not initialised", r.states);
  EXPECT_TRUE(r.failure.empty()) << path << ": " << r.failure;
}

TEST(StreamCorpus, EveryInputKeepsTheInvariants) {
  if (const char* one = std::getenv("GINS_STREAM_INPUT")) {
    Replay(one);
    return;
  }
  const std::filesystem::path dir = std::filesystem::path(GINS_SOURCE_DIR) / "tests/fuzz/corpus/stream";
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  ASSERT_GE(files.size(), 5u) << dir;
  size_t initialised = 0;
  for (const auto& f : files) {
    SCOPED_TRACE(f.filename().string());
    const std::vector<uint8_t> bytes = ReadBytes(f);
    const fuzz::StreamResult r = fuzz::RunStream(bytes.data(), bytes.size());
    EXPECT_TRUE(r.failure.empty()) << r.failure;
    initialised += r.initialized ? 1 : 0;
  }
  // Most seeds reach the estimators, not only the initialiser.
  EXPECT_GE(2 * initialised, files.size());
}

}  // namespace
}  // namespace gins
