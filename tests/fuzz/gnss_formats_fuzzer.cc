// libFuzzer target: the GNSS-format readers (core/io/gnss_formats.h, csv_columns.h) on an arbitrary file
// (plain or gzip), each under both damage policies and a small line-length limit: RTKLIB .pos, NMEA (with
// and without --date) and CSV through a GNSS and an IMU column map. Checks: no crash, no hang, only
// InputError escapes and its message is one line; every record is one the log reader accepts (finite, in
// range), times increase (a GVEL shares its fix's time), and the counts add up.

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

#include "core/io/csv_columns.h"
#include "core/io/gnss_formats.h"
#include "fuzz/fuzz_file.h"

namespace {

using gins::fuzz::Require;

enum class Reader { kPos, kNmea, kNmeaDated, kCsvGnss, kCsvImu };

std::unique_ptr<gins::RecordSource> Open(Reader which, const std::string& path, const gins::InputOptions& options) {
  gins::GnssFormatOptions format;
  switch (which) {
    case Reader::kPos:
      return gins::OpenRtklibPos(path, options, format);
    case Reader::kNmea:
      return gins::OpenNmea(path, options, format);
    case Reader::kNmeaDated:
      format.start_date_days = 16671;  // 2025-08-28
      format.time_scale = gins::LogTimeScale::kUnixUtc;
      return gins::OpenNmea(path, options, format);
    case Reader::kCsvGnss:
      return gins::OpenCsv(path,
                           gins::ParseColumnMap("t=1:ms,lat=2,lon=3:rad,h=4,se=5,sn=6,su=7,heading=8,ve=9,vn=10,vu=-11",
                                                gins::CsvKind::kGnss, "--gnss-columns"),
                           options);
    case Reader::kCsvImu:
      break;
  }
  return gins::OpenCsv(
      path,
      gins::ParseColumnMap("t=time:ns,gx=2:deg/s,gy=-3,gz=-4,ax=5:g,ay=6,az=7", gins::CsvKind::kImu, "--imu-columns"),
      options);
}

void ReadAll(Reader which, const std::string& path, const gins::InputOptions& options) {
  try {
    const std::unique_ptr<gins::RecordSource> source = Open(which, path, options);
    gins::LogRecord r;
    double last_t = -1.0;
    uint64_t records = 0;
    while (source->Next(&r)) {
      gins::LogRecord copy = r;
      gins::InputIssue issue;
      Require(gins::CheckLogRecord(&copy, &issue) == gins::LineParse::kRecord);
      // Strictly later, but for a GVEL at its fix's time.
      Require(r.t() > last_t || (r.is<gins::GnssVelocityRecord>() && r.t() == last_t));
      Require(r.line >= 1 && r.line <= source->file().lines);
      last_t = r.t();
      ++records;
    }
    const gins::ConvertedFile& f = source->file();
    Require(f.written == records);
    uint64_t by_type = 0;
    for (const uint64_t n : source->stats().records) by_type += n;
    Require(by_type == records);
    Require(f.total_skipped() <= f.lines + 1);  // +1: a gzip error after the last line
  } catch (const gins::InputError& e) {
    Require(std::string(e.what()).find('\n') == std::string::npos);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = gins::fuzz::WriteInput("gnss_formats", data, size);
  if (path.empty()) return 0;
  gins::InputOptions skip;
  skip.max_line_length = 300;  // small enough for the fuzzer to reach line_too_long
  skip.max_errors = 50;
  gins::InputOptions stop = skip;
  stop.on_error = gins::InputErrorPolicy::kStop;
  for (const Reader which : {Reader::kPos, Reader::kNmea, Reader::kNmeaDated, Reader::kCsvGnss, Reader::kCsvImu}) {
    ReadAll(which, path, skip);
    ReadAll(which, path, stop);
  }
  std::remove(path.c_str());
  return 0;
}
