#include "core/io/background_write.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <mutex>
#include <thread>
#include <vector>

namespace gins {
namespace {

constexpr size_t kMaxQueued = 2;  // chunks waiting for the writer thread

// The stream's cookie: owns the descriptor and the thread (started at the first chunk).
class BackgroundFd {
 public:
  explicit BackgroundFd(int fd) : fd_(fd) {}
  BackgroundFd(const BackgroundFd&) = delete;
  BackgroundFd& operator=(const BackgroundFd&) = delete;

  void Write(const char* data, size_t n) {
    std::unique_lock<std::mutex> lock(mutex_);
    if (!thread_.joinable()) thread_ = std::thread([this] { Run(); });
    space_.wait(lock, [this] { return queue_.size() < kMaxQueued; });
    if (error_ != 0) return;  // the file is lost; fclose reports it
    std::vector<char> chunk;
    if (!free_.empty()) {  // reused: its pages stay resident, no new memory per chunk
      chunk = std::move(free_.back());
      free_.pop_back();
    }
    chunk.assign(data, data + n);
    queue_.push_back(std::move(chunk));
    lock.unlock();
    ready_.notify_one();
  }

  // Waits for every chunk, stops the thread and closes the descriptor: 0, or -1 with errno the first error.
  int Close() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      closing_ = true;
    }
    ready_.notify_one();
    if (thread_.joinable()) thread_.join();
    int error = error_;
    if (::close(fd_) != 0 && error == 0) error = errno;
    if (error == 0) return 0;
    errno = error;
    return -1;
  }

 private:
  void Run() {
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      ready_.wait(lock, [this] { return !queue_.empty() || closing_; });
      if (queue_.empty()) return;  // closing and drained
      std::vector<char> chunk = std::move(queue_.front());
      const bool failed = error_ != 0;
      lock.unlock();
      const int error = failed ? 0 : WriteAll(chunk.data(), chunk.size());
      lock.lock();
      if (error != 0 && error_ == 0) error_ = error;
      queue_.pop_front();  // only now: the producer may fill at most kMaxQueued chunks meanwhile
      free_.push_back(std::move(chunk));
      space_.notify_one();
    }
  }

  int WriteAll(const char* p, size_t n) const {
    while (n > 0) {
      const ssize_t w = ::write(fd_, p, n);
      if (w < 0) {
        if (errno == EINTR) continue;
        return errno;
      }
      p += w;
      n -= static_cast<size_t>(w);
    }
    return 0;
  }

  const int fd_;
  std::mutex mutex_;
  std::condition_variable ready_, space_;
  std::deque<std::vector<char>> queue_;  // the front is being written while it is there
  std::vector<std::vector<char>> free_;
  int error_ = 0;  // the first write's errno
  bool closing_ = false;
  std::thread thread_;
};

ssize_t CookieWrite(void* cookie, const char* data, size_t n) {
  static_cast<BackgroundFd*>(cookie)->Write(data, n);
  return static_cast<ssize_t>(n);
}

int CookieClose(void* cookie) {
  auto* fd = static_cast<BackgroundFd*>(cookie);
  const int result = fd->Close();
  const int error = errno;
  delete fd;
  errno = error;
  return result;
}

}  // namespace

FILE* OpenBackgroundWriteStream(const std::string& path, char* buffer, size_t size) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd < 0) return nullptr;
  auto* cookie = new BackgroundFd(fd);
  cookie_io_functions_t io{};
  io.write = CookieWrite;
  io.close = CookieClose;
  FILE* f = ::fopencookie(cookie, "w", io);
  if (f == nullptr) {
    const int error = errno;
    cookie->Close();
    delete cookie;
    errno = error;
    return nullptr;
  }
  std::setvbuf(f, buffer, _IOFBF, size);
  return f;
}

}  // namespace gins
