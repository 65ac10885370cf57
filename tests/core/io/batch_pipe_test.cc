#include "core/io/batch_pipe.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <vector>

namespace gins {
namespace GINS_TEST_FILE {

TEST(BatchPipe, ConsumesEverythingInOrderOnAnotherThread) {
  std::vector<int> seen;
  std::thread::id consumer_thread;
  BatchPipe<int> pipe(
      [&](const int& v) {
        consumer_thread = std::this_thread::get_id();
        seen.push_back(v);
      },
      7, 2);
  for (int i = 0; i < 1000; ++i) pipe.Push(i);
  pipe.Close();
  ASSERT_EQ(seen.size(), 1000u);  // including the last, partial batch
  for (int i = 0; i < 1000; ++i) ASSERT_EQ(seen[static_cast<size_t>(i)], i);
  EXPECT_NE(consumer_thread, std::this_thread::get_id());
  pipe.Close();  // idempotent
}

// A slow consumer holds the producer back: never more than max_batches full batches plus the one being
// consumed and the one being filled are alive.
TEST(BatchPipe, BoundsWhatIsInFlight) {
  std::atomic<int> consumed{0}, max_ahead{0};
  std::atomic<int> pushed{0};
  constexpr size_t kBatch = 10, kMaxBatches = 3;
  BatchPipe<int> pipe(
      [&](const int&) {
        std::this_thread::sleep_for(std::chrono::microseconds(50));
        ++consumed;
      },
      kBatch, kMaxBatches);
  for (int i = 0; i < 500; ++i) {
    pipe.Push(i);
    ++pushed;
    max_ahead = std::max(max_ahead.load(), pushed.load() - consumed.load());
  }
  pipe.Close();
  EXPECT_EQ(consumed.load(), 500);
  EXPECT_LE(max_ahead.load(), static_cast<int>((kMaxBatches + 2) * kBatch));
}

TEST(BatchPipe, ConsumerExceptionIsRethrownByCloseAndTheProducerNeverBlocks) {
  int consumed = 0;
  BatchPipe<int> pipe(
      [&](const int& v) {
        if (v == 42) throw std::runtime_error("disk full");
        ++consumed;
      },
      4, 1);
  for (int i = 0; i < 10000; ++i) pipe.Push(i);  // would deadlock if the pipe stopped draining
  EXPECT_THROW(
      {
        try {
          pipe.Close();
        } catch (const std::runtime_error& e) {
          EXPECT_STREQ(e.what(), "disk full");
          throw;
        }
      },
      std::runtime_error);
  EXPECT_EQ(consumed, 42);  // nothing after the failure
  EXPECT_NO_THROW(pipe.Close());
}

TEST(BatchPipe, DestructorWithoutCloseConsumesAndJoins) {
  int consumed = 0;
  {
    BatchPipe<int> pipe([&](const int&) { ++consumed; }, 16, 2);
    for (int i = 0; i < 100; ++i) pipe.Push(i);
  }
  EXPECT_EQ(consumed, 100);
}

}  // namespace
}  // namespace gins
