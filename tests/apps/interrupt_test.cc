// Ctrl-C in `gins run` (apps/interrupt.h), on the real executable: the run is stopped while it waits for
// more of its log (a FIFO kept open), so the signal comes mid-run every time. It exits 128 + the signal at
// once, removes its unfinished files and leaves an earlier run's files in the same folder as they were.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "test_util.h"

namespace gins {
namespace GINS_TEST_FILE {

namespace fs = std::filesystem;

const std::string kSample = std::string(GINS_TEST_DATA_DIR) + "/sample/log.txt.gz";
const std::string kConfig = std::string(GINS_SOURCE_DIR) + "/config/default.yaml";

bool HasTemporaryFile(const std::string& dir) {
  if (!fs::exists(dir)) return false;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.path().filename().string().find(".tmp.") != std::string::npos) return true;
  }
  return false;
}

TEST(Interrupt, SignalMidRunRemovesItsUnfinishedFilesAndKeepsAnEarlierRun) {
  const std::string dir = test::MakeTempDir("interrupt_run");
  const std::string out = dir + "/out";
  const std::string earlier = std::string(GINS_BINARY) + " run --config " + kConfig + " --log " + kSample +
                              " --out " + out + " --mode eskf >/dev/null 2>&1";
  ASSERT_EQ(std::system(earlier.c_str()), 0);
  std::vector<std::pair<std::string, std::string>> before;
  for (const auto& e : fs::directory_iterator(out)) before.emplace_back(e.path().string(), test::ReadFile(e.path()));
  ASSERT_GE(before.size(), 4u);

  const std::string gz = test::ReadFile(kSample);
  const std::string fifo = dir + "/log.txt.gz";  // read as gzip by its name, as the sample is
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  for (const int sig : {SIGINT, SIGTERM}) {
    const std::string err_path = dir + "/stderr";
    const pid_t pid = ::fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      const int err = ::open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      if (err < 0 || ::dup2(err, 2) < 0 || ::dup2(err, 1) < 0) _exit(97);
      ::execl(GINS_BINARY, GINS_BINARY, "run", "--config", kConfig.c_str(), "--log", fifo.c_str(), "--out",
              out.c_str(), "--mode", "both", static_cast<char*>(nullptr));
      _exit(127);
    }
    const int in = ::open(fifo.c_str(), O_WRONLY);  // waits for gins to open it
    ASSERT_GE(in, 0);
    // Two thirds of the log: past initialisation, so the outputs are being written; then gins waits.
    const size_t part = gz.size() * 2 / 3;
    for (size_t done = 0; done < part;) {
      const ssize_t n = ::write(in, gz.data() + done, part - done);
      ASSERT_GT(n, 0);
      done += static_cast<size_t>(n);
    }
    for (int i = 0; i < 2000 && !HasTemporaryFile(out); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    ASSERT_TRUE(HasTemporaryFile(out)) << "gins run wrote no output within 20 s";
    ::kill(pid, sig);
    int status = 0;
    ASSERT_EQ(::waitpid(pid, &status, 0), pid);
    ::close(in);
    ASSERT_TRUE(WIFEXITED(status)) << "ended by signal " << WTERMSIG(status);
    EXPECT_EQ(WEXITSTATUS(status), 128 + sig);
    const std::string err = test::ReadFile(err_path);
    EXPECT_NE(err.find(sig == SIGINT ? "gins: interrupted by SIGINT: " : "gins: interrupted by SIGTERM: "),
              std::string::npos)
        << err;
    EXPECT_FALSE(HasTemporaryFile(out));
    size_t files = 0;
    for (const auto& e : fs::directory_iterator(out)) {
      (void)e;
      ++files;
    }
    EXPECT_EQ(files, before.size());
    for (const auto& [path, text] : before) EXPECT_TRUE(test::ReadFile(path) == text) << path;
  }
}

}  // namespace
}  // namespace gins
