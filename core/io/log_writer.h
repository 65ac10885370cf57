// Writes a gins log (docs/formats.md §3) completely or not at all (AtomicFile): plain text, or gzip when the path
// ends in ".gz". Numbers are written in their shortest form that reads back to the same double, so a log
// written here and read by LogReader holds exactly the values given.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include "core/io/log_record.h"
#include "core/io/trajectory_writer.h"
#include "core/measurements.h"

namespace gins {

class LogWriter {
 public:
  // Throws std::runtime_error if the file cannot be created.
  explicit LogWriter(const std::string& path);
  ~LogWriter();
  LogWriter(const LogWriter&) = delete;
  LogWriter& operator=(const LogWriter&) = delete;

  // "# <text>" (one line: newlines in text become spaces).
  void Comment(std::string_view text);
  // "<token> t <fields>": IMU t gx gy gz ax ay az, ODOM t left_pulses right_pulses, GNSS t lat lon alt
  // heading valid [σe σn σu] (the heading 0 when not valid), GVEL t ve vn vu [σe σn σu].
  void Add(const LogRecord& r);
  // Finishes the file and renames it into place; throws std::runtime_error on any I/O error. Without
  // Commit() the file never appears.
  void Commit();

  uint64_t records() const { return records_; }
  const std::string& path() const { return file_.path(); }

 private:
  class Gzip;
  template <typename R>
  void Write(const R& m);
  void Put(std::string_view text);
  void Flush();

  AtomicFile file_;
  std::unique_ptr<Gzip> gzip_;  // null: plain text
  std::string buf_;             // text not yet handed on
  uint64_t records_ = 0;
};

}  // namespace gins
