// The API's reorder buffer: within the window, any arrival order comes out sorted (equal times in arrival
// order); older than the window is late; window 0 passes in-order records straight through.
#include "apps/api/reorder_buffer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

namespace gins::api {
namespace GINS_TEST_FILE {

LogRecord At(double t, uint64_t tag) {
  ImuSample imu;
  imu.t = t;
  return {imu, tag};
}

TEST(ApiReorderBufferTest, SortsAnyOrderWithinTheWindow) {
  std::mt19937 rng(7);
  std::vector<LogRecord> in;
  for (int i = 0; i < 500; ++i) in.push_back(At(1.0 + 0.01 * (i / 2), static_cast<uint64_t>(i)));  // pairs share t
  // Each record moved at most 4 places: at most 0.02 s late at 2 records per 0.01 s, within a 0.05 s window.
  for (size_t i = 0; i + 4 < in.size(); i += 5) std::shuffle(in.begin() + i, in.begin() + i + 5, rng);
  ReorderBuffer buffer(0.05);
  std::vector<LogRecord> out;
  auto keep = [&](const LogRecord& r) { out.push_back(r); };
  for (const LogRecord& r : in) ASSERT_TRUE(buffer.Add(r, keep)) << r.t();
  EXPECT_LT(out.size(), in.size());  // the last window is still held
  buffer.Flush(keep);
  ASSERT_EQ(out.size(), in.size());
  for (size_t i = 1; i < out.size(); ++i) {
    ASSERT_LE(out[i - 1].t(), out[i].t()) << i;
    // Equal times: arrival order.
    if (out[i - 1].t() == out[i].t()) {
      const auto pos = [&](uint64_t tag) {
        return std::find_if(in.begin(), in.end(), [&](const LogRecord& r) { return r.line == tag; }) - in.begin();
      };
      EXPECT_LT(pos(out[i - 1].line), pos(out[i].line));
    }
  }
  EXPECT_GT(buffer.reordered(), 0u);
}

TEST(ApiReorderBufferTest, OlderThanTheWindowIsLate) {
  ReorderBuffer buffer(0.5);
  std::vector<double> out;
  auto keep = [&](const LogRecord& r) { out.push_back(r.t()); };
  EXPECT_TRUE(buffer.Add(At(10.0, 0), keep));
  EXPECT_TRUE(buffer.Add(At(9.5, 1), keep));    // exactly the window: sorted in
  EXPECT_FALSE(buffer.Add(At(9.49, 2), keep));  // late
  EXPECT_TRUE(buffer.Add(At(10.6, 3), keep));
  EXPECT_EQ(out, (std::vector<double>{9.5, 10.0}));
  EXPECT_FALSE(buffer.Add(At(10.0, 4), keep));  // older than what was handed on: late, never out of order
  buffer.Flush(keep);
  EXPECT_EQ(out, (std::vector<double>{9.5, 10.0, 10.6}));
  EXPECT_EQ(buffer.reordered(), 1u);
}

TEST(ApiReorderBufferTest, WindowZeroPassesInOrderRecordsStraightThrough) {
  ReorderBuffer buffer(0.0);
  std::vector<double> out;
  auto keep = [&](const LogRecord& r) { out.push_back(r.t()); };
  EXPECT_TRUE(buffer.Add(At(1.0, 0), keep));
  EXPECT_TRUE(buffer.Add(At(1.0, 1), keep));  // the same time stamp is in order
  EXPECT_EQ(out.size(), 2u);
  EXPECT_EQ(buffer.held(), 0u);
  EXPECT_FALSE(buffer.Add(At(0.999, 2), keep));
  EXPECT_EQ(buffer.reordered(), 0u);
}

}  // namespace
}  // namespace gins::api
