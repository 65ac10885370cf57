// LogReader on a pipe (`gins stream`'s stdin): a line is handed on as soon as it arrives, a stop fd ends
// the data after the last complete line, gzip is refused, and damage is counted as in a file.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <future>
#include <string>

#include "core/io/log_reader.h"

namespace gins {
namespace GINS_TEST_FILE {

std::string Imu(const std::string& t) { return "IMU " + t + " 0.01 -0.02 0.03 0.1 -0.2 9.8\n"; }

class Pipe {
 public:
  Pipe() { EXPECT_EQ(::pipe(fds_), 0); }
  ~Pipe() {
    CloseWrite();
    ::close(fds_[0]);
  }
  int read_end() const { return fds_[0]; }
  void Write(const std::string& text) {
    ASSERT_EQ(::write(fds_[1], text.data(), text.size()), static_cast<ssize_t>(text.size()));
  }
  void CloseWrite() {
    if (fds_[1] >= 0) ::close(fds_[1]);
    fds_[1] = -1;
  }

 private:
  int fds_[2] = {-1, -1};
};

// Next() on another thread, so that a reader that waits for more data fails the test instead of hanging it.
bool NextWithin(LogReader* reader, LogRecord* record, Pipe* unblock) {
  auto next = std::async(std::launch::async, [&] { return reader->Next(record); });
  if (next.wait_for(std::chrono::seconds(5)) == std::future_status::timeout) {
    ADD_FAILURE() << "the reader waited for more than the line that had arrived";
    unblock->CloseWrite();
    next.wait();
    return false;
  }
  return next.get();
}

TEST(StreamInputTest, HandsOnEachLineAsItArrives) {
  Pipe data;
  LogReader reader(data.read_end(), "<stdin>", InputOptions{});
  data.Write(Imu("1.00"));
  LogRecord record;
  ASSERT_TRUE(NextWithin(&reader, &record, &data));
  EXPECT_EQ(record.t(), 1.0);
  EXPECT_EQ(record.line, 1u);
  data.Write("IMU 1.01 0.01 nan\n" + Imu("1.02"));  // the damage policy of a file
  ASSERT_TRUE(NextWithin(&reader, &record, &data));
  EXPECT_EQ(record.t(), 1.02);
  EXPECT_EQ(record.line, 3u);
  data.CloseWrite();
  EXPECT_FALSE(reader.Next(&record));
  EXPECT_FALSE(reader.stopped());
  EXPECT_EQ(CountOf<ImuSample>(reader.stats().records), 2u);
  EXPECT_EQ(reader.stats().total_skipped(), 1u);
}

TEST(StreamInputTest, StopEndsAfterTheLastCompleteLine) {
  Pipe data, stop;
  data.Write(Imu("1.00") + Imu("1.01") + "IMU 1.02 0.01 -0.0");  // the last line is cut by the stop
  LogReader reader(data.read_end(), "<stdin>", InputOptions{}, stop.read_end());
  LogRecord record;
  ASSERT_TRUE(NextWithin(&reader, &record, &data));
  stop.Write("x");
  ASSERT_TRUE(NextWithin(&reader, &record, &data));  // already read: still handed on
  EXPECT_EQ(record.t(), 1.01);
  EXPECT_FALSE(reader.Next(&record));
  EXPECT_TRUE(reader.stopped());
  EXPECT_EQ(reader.stats().total_skipped(), 0u);  // the fragment is not damage
  EXPECT_EQ(reader.stats().lines, 2u);
}

TEST(StreamInputTest, RefusesGzip) {
  Pipe data;
  data.Write(std::string("\x1f\x8b\x08\x00\x00\x00", 6));
  data.CloseWrite();
  LogReader reader(data.read_end(), "<stdin>", InputOptions{});
  LogRecord record;
  try {
    reader.Next(&record);
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("<stdin>: gzip data"), std::string::npos) << e.what();
  }
}

TEST(StreamInputTest, ShortStreamsAndBom) {
  Pipe empty;
  empty.CloseWrite();
  LogReader reader(empty.read_end(), "<stdin>", InputOptions{});
  LogRecord record;
  EXPECT_FALSE(reader.Next(&record));
  EXPECT_EQ(reader.stats().lines, 0u);

  Pipe bom;
  bom.Write("\xEF\xBB\xBF" + Imu("2"));
  bom.CloseWrite();
  LogReader with_bom(bom.read_end(), "<stdin>", InputOptions{});
  ASSERT_TRUE(with_bom.Next(&record));
  EXPECT_EQ(record.t(), 2.0);
}

}  // namespace
}  // namespace gins
