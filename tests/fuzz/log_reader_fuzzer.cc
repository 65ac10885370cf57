// libFuzzer target: the whole LogReader (plain or gzip, detected by content) on an arbitrary file, under
// both damage policies and a small line-length limit. Checks: no crash, no hang, only InputError escapes,
// records come out finite and in time order within input.reorder_window_s (the API's reorder buffer sorts
// them), and every line is accounted for.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <numeric>
#include <string>

#include "core/io/log_reader.h"
#include "fuzz/fuzz_file.h"

namespace {

using gins::fuzz::Require;

void ReadAll(const std::string& path, const gins::InputOptions& options) {
  try {
    gins::LogReader reader(path, options);
    gins::LogRecord record;
    double newest_t = -1.0;
    uint64_t records = 0;
    while (reader.Next(&record)) {
      Require(std::isfinite(record.t()) && record.t() >= newest_t - options.reorder_window);
      Require(record.line >= 1 && record.line <= reader.stats().lines);
      newest_t = std::max(newest_t, record.t());
      ++records;
    }
    const gins::ReadStats& s = reader.stats();
    Require(std::accumulate(s.records.begin(), s.records.end(), uint64_t{0}) == records);
    uint64_t listed = 0;
    for (const auto& [reason, lines] : s.skipped_lines) {
      Require(lines.size() == s.skipped.at(reason));
      listed += lines.size();
    }
    Require(listed == s.total_skipped());
    Require(records + s.total_skipped() <= s.lines + 1);  // +1: a gzip error after the last line
  } catch (const gins::InputError& e) {
    Require(std::string(e.what()).find('\n') == std::string::npos);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = gins::fuzz::WriteInput("log_reader", data, size);
  if (path.empty()) return 0;
  gins::InputOptions skip;
  skip.max_line_length = 200;  // small enough for the fuzzer to reach line_too_long
  skip.max_errors = 50;
  skip.max_time_jump = 100.0;
  ReadAll(path, skip);
  gins::InputOptions stop = skip;
  stop.on_error = gins::InputErrorPolicy::kStop;
  ReadAll(path, stop);
  std::remove(path.c_str());
  return 0;
}
