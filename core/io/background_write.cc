#include "core/io/background_write.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <system_error>
#include <vector>

#include "core/io/batch_pipe.h"

namespace gins {
namespace {

// The stream's cookie: owns the descriptor and the pipe whose thread writes the chunks to it, in order. One
// chunk waits while another is written; a failed write drops the rest (BatchPipe) and is reported at Close.
class BackgroundFd {
 public:
  explicit BackgroundFd(int fd)
      : fd_(fd),
        pipe_([this](const std::vector<char>& chunk) { WriteAll(chunk); }, /*batch_size=*/1,
              /*max_batches=*/1) {}

  void Write(const char* data, size_t n) { pipe_.Push(std::vector<char>(data, data + n)); }

  // Waits for every chunk, stops the thread and closes the descriptor: 0, or -1 with errno the first error.
  int Close() {
    int error = 0;
    try {
      pipe_.Close();
    } catch (const std::system_error& e) {
      error = e.code().value();
    }
    if (::close(fd_) != 0 && error == 0) error = errno;
    if (error == 0) return 0;
    errno = error;
    return -1;
  }

 private:
  void WriteAll(const std::vector<char>& chunk) const {
    const char* p = chunk.data();
    size_t n = chunk.size();
    while (n > 0) {
      const ssize_t w = ::write(fd_, p, n);
      if (w < 0) {
        if (errno == EINTR) continue;
        throw std::system_error(errno, std::generic_category());
      }
      p += w;
      n -= static_cast<size_t>(w);
    }
  }

  const int fd_;
  BatchPipe<std::vector<char>> pipe_;  // last: its thread writes to fd_
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
