#include "core/io/read_ahead.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>

namespace gins {
namespace GINS_TEST_FILE {

TEST(ReadAhead, YieldsEverythingInOrderFromAnotherThread) {
  int next = 0;
  std::thread::id producer_thread;
  ReadAhead<int> ahead(
      [&](int* v) {
        producer_thread = std::this_thread::get_id();
        if (next == 1000) return false;
        *v = next++;
        return true;
      },
      7, 2);
  int v = -1;
  for (int i = 0; i < 1000; ++i) {
    ASSERT_TRUE(ahead.Next(&v));
    ASSERT_EQ(v, i);
  }
  EXPECT_FALSE(ahead.Next(&v));
  EXPECT_FALSE(ahead.Next(&v));  // the end stays the end
  EXPECT_NE(producer_thread, std::this_thread::get_id());
}

// The producer's exception comes after every item produced before it, as a direct call would have thrown.
TEST(ReadAhead, ProducerExceptionIsRethrownInItsPlace) {
  int next = 0;
  ReadAhead<int> ahead(
      [&](int* v) {
        if (next == 42) throw std::runtime_error("log.txt:43: bad record");
        *v = next++;
        return true;
      },
      5, 3);
  int v = -1;
  for (int i = 0; i < 42; ++i) {
    ASSERT_TRUE(ahead.Next(&v));
    ASSERT_EQ(v, i);
  }
  try {
    ahead.Next(&v);
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "log.txt:43: bad record");
  }
}

// Bounded: a consumer that does not read holds the producer back; destroying it stops an endless producer.
TEST(ReadAhead, BoundsWhatIsReadAheadAndStopsWhenTheConsumerLeaves) {
  std::atomic<int> produced{0};
  constexpr size_t kBatch = 10, kMaxBatches = 3;
  {
    ReadAhead<int> ahead(
        [&](int* v) {
          *v = produced++;
          return true;  // endless
        },
        kBatch, kMaxBatches);
    int v = -1;
    ASSERT_TRUE(ahead.Next(&v));
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    // The batch being read, the full ones waiting, and the one being filled.
    EXPECT_LE(produced.load(), static_cast<int>((kMaxBatches + 2) * kBatch));
  }
  EXPECT_GT(produced.load(), 0);
}

}  // namespace
}  // namespace gins
