// `gins stream` through a pipe, as a user runs it: the same bytes as `gins run`'s files in both modes and
// both formats, each state written before the input ends, SIGTERM/SIGINT ending cleanly with what was read,
// the damage policy of `gins run`, and its errors.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/ioctl.h>
#include <sys/wait.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "test_util.h"

namespace gins {
namespace GINS_TEST_FILE {

const std::string kSample = std::string(GINS_TEST_DATA_DIR) + "/sample/log.txt.gz";
const std::string kConfig = std::string(GINS_SOURCE_DIR) + "/config/default.yaml";

std::string Gunzip(const std::string& path) {
  gzFile f = gzopen(path.c_str(), "rb");
  EXPECT_NE(f, nullptr);
  std::string text;
  char buf[1 << 16];
  int n;
  while ((n = gzread(f, buf, sizeof(buf))) > 0) text.append(buf, static_cast<size_t>(n));
  gzclose(f);
  return text;
}

const std::string& SampleText() {
  static const std::string text = Gunzip(kSample);
  return text;
}

// The first n lines of a text.
std::string Head(const std::string& text, size_t n) {
  size_t pos = 0;
  for (size_t i = 0; i < n && pos != std::string::npos; ++i) {
    pos = text.find('\n', pos);
    if (pos != std::string::npos) ++pos;
  }
  return pos == std::string::npos ? text : text.substr(0, pos);
}

size_t CountLines(const std::string& text) {
  size_t n = 0;
  for (char c : text) n += c == '\n';
  return n;
}

// The gins binary with stdin from a pipe we write, stdout and stderr to files.
class Gins {
 public:
  Gins(const std::vector<std::string>& args, const std::string& dir) : out_(dir + "/stdout"), err_(dir + "/stderr") {
    int fds[2];
    EXPECT_EQ(::pipe(fds), 0);
    pid_ = ::fork();
    if (pid_ == 0) {
      ::dup2(fds[0], 0);
      ::close(fds[0]);
      ::close(fds[1]);
      const int out = ::open(out_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      const int err = ::open(err_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      if (out < 0 || err < 0) _exit(97);
      ::dup2(out, 1);
      ::dup2(err, 2);
      std::vector<char*> argv = {const_cast<char*>(GINS_BINARY)};
      for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
      argv.push_back(nullptr);
      ::execv(GINS_BINARY, argv.data());
      _exit(127);
    }
    ::close(fds[0]);
    in_ = fds[1];
  }
  ~Gins() {
    CloseInput();
    if (pid_ > 0) Wait();
  }

  // Stops early if the child has stopped reading (it refused the input).
  void Write(const std::string& text) {
    ::signal(SIGPIPE, SIG_IGN);  // EPIPE instead
    size_t done = 0;
    while (done < text.size()) {
      const ssize_t n = ::write(in_, text.data() + done, text.size() - done);
      if (n < 0 && errno == EPIPE) return;
      ASSERT_GT(n, 0);
      done += static_cast<size_t>(n);
    }
  }
  void CloseInput() {
    if (in_ >= 0) ::close(in_);
    in_ = -1;
  }
  // Waits until the child has read everything written so far (the pipe is empty).
  void WaitUntilRead() {
    for (int i = 0; i < 2000; ++i) {
      int unread = 0;
      ASSERT_EQ(::ioctl(in_, FIONREAD, &unread), 0);
      if (unread == 0) return;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    FAIL() << "gins stream did not read its input";
  }
  void Signal(int sig) { ::kill(pid_, sig); }
  int Wait() {
    int status = 0;
    ::waitpid(pid_, &status, 0);
    pid_ = -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  }
  std::string Out() const { return test::ReadFile(out_); }
  std::string Err() const { return test::ReadFile(err_); }

 private:
  std::string out_, err_;
  pid_t pid_ = -1;
  int in_ = -1;
};

// `gins run` on a log file, in a child; returns its exit code.
int GinsRun(const std::string& log, const std::string& out, const std::string& mode,
            const std::string& config = kConfig) {
  const std::string cmd = std::string(GINS_BINARY) + " run --config " + config + " --log " + log + " --out " + out +
                          " --mode " + mode + " >/dev/null 2>&1";
  return std::system(cmd.c_str());
}

// gins stream over all of `text`; returns its stdout.
std::string Stream(const std::vector<std::string>& args, const std::string& text, const std::string& dir,
                   int* code = nullptr, std::string* err = nullptr) {
  Gins gins(args, dir);
  gins.Write(text);
  gins.CloseInput();
  const int c = gins.Wait();
  if (code != nullptr) *code = c;
  if (err != nullptr) *err = gins.Err();
  return gins.Out();
}

TEST(StreamCliTest, EqualsRunInBothModesAndFormats) {
  const std::string dir = test::MakeTempDir("stream_equals_run");
  ASSERT_EQ(GinsRun(kSample, dir + "/run", "both"), 0);
  struct Case {
    std::vector<std::string> args;
    std::string file;
  };
  const std::vector<Case> cases = {
      {{"--mode", "eskf"}, "eskf.tum"},
      {{"--mode", "eskf", "--out-format", "csv"}, "eskf_states.csv"},
      {{"--mode", "smoother"}, "smoother.tum"},
      {{"--mode", "smoother", "--out-format", "csv"}, "smoother_states.csv"},
      {{"--mode", "smoother", "--online"}, "smoother_online.tum"},
      {{"--mode", "eskf", "--out-format", "lla"}, "eskf_lla.csv"},
      {{"--mode", "smoother", "--out-format", "lla"}, "smoother_lla.csv"},
  };
  for (const Case& c : cases) {
    std::vector<std::string> args = {"stream", "--config", kConfig};
    args.insert(args.end(), c.args.begin(), c.args.end());
    int code = -1;
    std::string err;
    const std::string out = Stream(args, SampleText(), dir, &code, &err);
    EXPECT_EQ(code, 0) << err;
    const std::string expected = test::ReadFile(dir + "/run/" + c.file);
    EXPECT_GT(CountLines(expected), 100u);
    EXPECT_TRUE(out == expected) << c.file << ": " << CountLines(out) << " lines streamed, " << CountLines(expected)
                                 << " in the run's file";
    EXPECT_NE(err.find("19969 lines: 18001 IMU, 1800 ODOM, 166 GNSS"), std::string::npos) << err;
  }
}

// Latency: each IMU line after initialisation gives its ESKF state while the input is still open.
TEST(StreamCliTest, WritesEachStateBeforeTheInputEnds) {
  const std::string dir = test::MakeTempDir("stream_latency");
  Gins gins({"stream", "--config", kConfig, "--mode", "eskf"}, dir);
  const std::string first = Head(SampleText(), 3000);
  gins.Write(first);
  gins.WaitUntilRead();
  size_t lines = 0;
  for (int i = 0; i < 400 && lines < 2; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    lines = CountLines(gins.Out());
  }
  ASSERT_GE(lines, 2u) << "no state within 20 s of 3000 lines";
  // Ten more IMU lines: ten more states, while the pipe stays open.
  const std::string rest = SampleText().substr(first.size());
  const std::string next = Head(rest, 12);  // the sample has an ODOM every 10 IMU
  const size_t imu = static_cast<size_t>(std::count(next.begin(), next.end(), 'I'));
  gins.Write(next);
  gins.WaitUntilRead();
  size_t now = lines;
  for (int i = 0; i < 200 && now < lines + imu; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(25));
    now = CountLines(gins.Out());
  }
  EXPECT_EQ(now, lines + imu);
  gins.Write(rest.substr(next.size()));
  gins.CloseInput();
  EXPECT_EQ(gins.Wait(), 0) << gins.Err();
  ASSERT_EQ(GinsRun(kSample, dir + "/run", "eskf"), 0);
  EXPECT_TRUE(gins.Out() == test::ReadFile(dir + "/run/eskf.tum"));
}

// A signal ends the input after what was read; the result is `gins run` on exactly those lines (the
// smoother's window flushed).
TEST(StreamCliTest, SigtermAndSigintEndCleanlyWithWhatWasRead) {
  const std::string dir = test::MakeTempDir("stream_signal");
  const std::string part = Head(SampleText(), 6000);
  test::WriteFile(dir + "/part.txt", part);
  for (const std::string mode : {"eskf", "smoother"}) {
    ASSERT_EQ(GinsRun(dir + "/part.txt", dir + "/run_" + mode, mode), 0);
    for (const int sig : {SIGTERM, SIGINT}) {
      Gins gins({"stream", "--config", kConfig, "--mode", mode}, dir);
      gins.Write(part + "IMU 1700000060.010000 0.001 0.002");  // and a line cut short by the signal
      gins.WaitUntilRead();
      gins.Signal(sig);
      EXPECT_EQ(gins.Wait(), 0) << gins.Err();
      EXPECT_TRUE(gins.Out() == test::ReadFile(dir + "/run_" + mode + "/" + mode + ".tum")) << mode << " " << sig;
      EXPECT_NE(gins.Err().find(sig == SIGTERM ? "ended by SIGTERM" : "ended by SIGINT"), std::string::npos)
          << gins.Err();
      EXPECT_NE(gins.Err().find("0 damaged lines"), std::string::npos) << gins.Err();
    }
  }
}

// Damaged lines: skipped and counted as `gins run` skips them; with on_error: stop, the first stops it.
TEST(StreamCliTest, DamagedLinesFollowTheRunPolicy) {
  const std::string dir = test::MakeTempDir("stream_damage");
  std::istringstream in(SampleText());
  std::string line, damaged;
  for (int i = 1; std::getline(in, line); ++i) {
    damaged += line + "\n";
    if (i == 4000) damaged += "IMU 1700000030.0 0.1 abc 0.1 0.1 0.1 9.8\n";
    if (i == 8000) damaged += "GNSS 1600000000 31.5 120.4 10 0 0\n";  // out of order
    if (i == 9000) damaged += "WHEEL 1700000080 1 2\n";
  }
  test::WriteFile(dir + "/damaged.txt", damaged);
  ASSERT_EQ(GinsRun(dir + "/damaged.txt", dir + "/run", "eskf"), 0);
  int code = -1;
  std::string err;
  const std::string out = Stream({"stream", "--config", kConfig}, damaged, dir, &code, &err);
  EXPECT_EQ(code, 0) << err;
  EXPECT_TRUE(out == test::ReadFile(dir + "/run/eskf.tum"));
  EXPECT_NE(err.find("3 damaged lines skipped (bad_number 1 out_of_order 1 unknown_type 1)"), std::string::npos) << err;

  test::WriteFile(dir + "/stop.yaml", "input:\n  on_error: stop\n");
  Stream({"stream", "--config", dir + "/stop.yaml"}, damaged, dir, &code, &err);
  EXPECT_EQ(code, 1);
  EXPECT_NE(err.find("gins: error: <stdin>:4001: bad_number: field 4 (gy) 'abc' is not a number"), std::string::npos)
      << err;
}

// GNSS lines that arrive 0.15 s late (as from a live receiver): with input.reorder_window_s 0.2 both
// gins stream and gins run sort them into place and give the states of the log in time order; without the
// window they are out_of_order damage in both.
TEST(StreamCliTest, LateLinesWithinTheReorderWindowAreSortedInBothCommands) {
  const std::string dir = test::MakeTempDir("stream_reorder");
  std::istringstream in(SampleText());
  std::string line, late;
  std::vector<std::pair<double, std::string>> waiting;
  size_t moved = 0;
  double t_first = -1.0;
  while (std::getline(in, line)) {
    const double t = line[0] == '#' ? 0.0 : std::stod(line.substr(line.find(' ') + 1));
    while (!waiting.empty() && t > waiting.front().first + 0.15) {
      late += waiting.front().second + "\n";
      waiting.erase(waiting.begin());
      ++moved;
    }
    // From 30 s on: the first fixes arrive in time, so the run initialises even when the late ones are
    // refused (the initialiser needs a few fixes, not one at the end of the log).
    if (t_first < 0.0 && line[0] != '#') t_first = t;
    if (line.rfind("GNSS", 0) == 0 && t >= t_first + 30.0) {
      waiting.emplace_back(t, line);
    } else {
      late += line + "\n";
    }
  }
  for (const auto& w : waiting) late += w.second + "\n";
  ASSERT_GT(moved, 100u);
  test::WriteFile(dir + "/late.txt", late);
  test::WriteFile(dir + "/reorder.yaml", "input:\n  reorder_window_s: 0.2\n");
  ASSERT_EQ(GinsRun(kSample, dir + "/in_order", "eskf"), 0);
  const std::string expected = test::ReadFile(dir + "/in_order/eskf.tum");
  int code = -1;
  std::string err;
  EXPECT_TRUE(Stream({"stream", "--config", dir + "/reorder.yaml"}, late, dir, &code, &err) == expected);
  EXPECT_EQ(code, 0) << err;
  EXPECT_NE(err.find("0 damaged lines"), std::string::npos) << err;
  ASSERT_EQ(GinsRun(dir + "/late.txt", dir + "/run_late", "eskf", dir + "/reorder.yaml"), 0);
  EXPECT_TRUE(test::ReadFile(dir + "/run_late/eskf.tum") == expected);

  Stream({"stream", "--config", kConfig}, late, dir, &code, &err);
  EXPECT_EQ(code, 0) << err;
  EXPECT_NE(err.find("out_of_order " + std::to_string(moved)), std::string::npos) << err;
}

TEST(StreamCliTest, InputWithoutASolutionIsAnError) {
  const std::string dir = test::MakeTempDir("stream_errors");
  std::istringstream in(Head(SampleText(), 500));
  std::string line, imu_only;
  while (std::getline(in, line)) {
    if (line.rfind("IMU", 0) == 0) imu_only += line + "\n";
  }
  int code = -1;
  std::string err;
  const std::string out = Stream({"stream", "--config", kConfig}, imu_only, dir, &code, &err);
  EXPECT_EQ(code, 1);
  EXPECT_EQ(out, "");
  EXPECT_NE(err.find("gins: error: <stdin>: no usable GNSS records"), std::string::npos) << err;

  Stream({"stream", "--config", kConfig}, "", dir, &code, &err);
  EXPECT_EQ(code, 1);
  EXPECT_NE(err.find("<stdin>: empty log"), std::string::npos) << err;

  Stream({"stream", "--config", kConfig, "--online"}, "", dir, &code, &err);
  EXPECT_EQ(code, 2);
  EXPECT_NE(err.find("--online needs --mode smoother"), std::string::npos) << err;
}

}  // namespace
}  // namespace gins
