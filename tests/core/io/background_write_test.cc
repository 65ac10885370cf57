// The stream whose writes run on their own thread: every byte arrives in order, and a failed write is
// reported by fclose.
#include "core/io/background_write.h"

#include <gtest/gtest.h>

#include <cerrno>
#include <cstdio>
#include <memory>
#include <string>

#include "tests/test_util.h"

namespace gins {
namespace GINS_TEST_FILE {

// Small lines through the buffer and writes larger than it (stdio hands those over whole) interleave in
// order, over many more chunks than may wait at once.
TEST(BackgroundWriteStream, EveryByteArrivesInOrder) {
  const std::string path = test::MakeTempDir("background_write") + "/out.txt";
  constexpr size_t kBuffer = 4096;
  auto buffer = std::make_unique<char[]>(kBuffer);
  FILE* f = OpenBackgroundWriteStream(path, buffer.get(), kBuffer);
  ASSERT_NE(f, nullptr);
  std::string expected;
  for (int i = 0; i < 20000; ++i) {
    char line[32];
    const int n = std::snprintf(line, sizeof(line), "%d\n", i);
    ASSERT_EQ(std::fwrite(line, 1, static_cast<size_t>(n), f), static_cast<size_t>(n));
    expected.append(line, static_cast<size_t>(n));
    if (i % 997 == 0) {
      const std::string big(3 * kBuffer + 17, static_cast<char>('a' + i % 26));
      ASSERT_EQ(std::fwrite(big.data(), 1, big.size(), f), big.size());
      expected += big;
    }
  }
  ASSERT_EQ(std::fclose(f), 0);
  ASSERT_GT(expected.size(), 50 * kBuffer);
  EXPECT_EQ(test::ReadFile(path), expected);
}

TEST(BackgroundWriteStream, AnEmptyFileIsCreated) {
  const std::string path = test::MakeTempDir("background_write_empty") + "/out.txt";
  char buffer[64];
  FILE* f = OpenBackgroundWriteStream(path, buffer, sizeof(buffer));
  ASSERT_NE(f, nullptr);
  ASSERT_EQ(std::fclose(f), 0);
  EXPECT_EQ(test::ReadFile(path), "");
}

// A device that refuses every write (the disk full): fwrite cannot tell, fclose does, with the errno.
TEST(BackgroundWriteStream, AFailedWriteIsReportedByFclose) {
  char buffer[256];
  FILE* f = OpenBackgroundWriteStream("/dev/full", buffer, sizeof(buffer));
  ASSERT_NE(f, nullptr);
  const std::string data(10000, 'x');
  std::fwrite(data.data(), 1, data.size(), f);
  errno = 0;
  EXPECT_EQ(std::fclose(f), EOF);
  EXPECT_EQ(errno, ENOSPC);
}

TEST(BackgroundWriteStream, AFileThatCannotBeCreatedGivesNullAndErrno) {
  char buffer[64];
  errno = 0;
  EXPECT_EQ(OpenBackgroundWriteStream("/nonexistent_dir_gins/out.txt", buffer, sizeof(buffer)), nullptr);
  EXPECT_EQ(errno, ENOENT);
}

}  // namespace
}  // namespace gins
