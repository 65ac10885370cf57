// What the file-reading fuzzers share: a failed invariant aborts (libFuzzer reports it as a crash), and
// each input goes to a temporary file of this process, as a reader gets it.
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace gins::fuzz {

inline void Require(bool ok) {
  if (!ok) std::abort();
}

// The input written to $TMPDIR/gins_<name>_fuzzer.<pid> (the same path each time); "" if it cannot be.
inline std::string WriteInput(const char* name, const uint8_t* data, size_t size) {
  const char* dir = std::getenv("TMPDIR");
  const std::string path =
      std::string(dir != nullptr ? dir : "/tmp") + "/gins_" + name + "_fuzzer." + std::to_string(getpid());
  FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) return "";
  if (size > 0) std::fwrite(data, 1, size, f);
  std::fclose(f);
  return path;
}

}  // namespace gins::fuzz
