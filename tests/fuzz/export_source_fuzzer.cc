// libFuzzer target: `gins export`'s reader (core/io/geo_export.h) on an arbitrary file, read as each kind it
// tells apart (truth, geodetic track, states CSV, TUM), then converted and written in every format. Checks:
// no crash, no hang, only InputError escapes (one line), the samples come out finite and strictly increasing
// in time, and no format writes a "nan" or "inf".

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "core/io/geo_export.h"
#include "core/io/geo_formats.h"
#include "core/io/log_reader.h"
#include "fuzz/fuzz_file.h"

namespace {

using gins::fuzz::Require;

// Writes with `write` into memory and checks the text holds no non-finite number.
template <typename F>
void RequireFiniteText(F write) {
  char* buf = nullptr;
  size_t size = 0;
  std::FILE* f = open_memstream(&buf, &size);
  Require(f != nullptr);
  try {
    write(f);
  } catch (const gins::InputError& e) {
    Require(std::strchr(e.what(), '\n') == nullptr);
  }
  std::fclose(f);
  const std::string text(buf, size);
  std::free(buf);
  Require(text.find("nan") == std::string::npos && text.find("inf") == std::string::npos);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = gins::fuzz::WriteInput("export_source", data, size);
  if (path.empty()) return 0;
  try {
    const gins::ExportSource src = gins::ReadExportSource(path, gins::GeodeticPoint{31.5, 120.4, 10.0});
    double last_t = -HUGE_VAL;
    for (const gins::TrajectorySample& s : src.trajectory.samples) {
      Require(std::isfinite(s.t) && s.t > last_t && s.p_w.allFinite());
      last_t = s.t;
    }
    gins::GeoTrack track = gins::ToGeoTrack(src, "fuzz");
    track.no_fix.push_back({track.samples.front().t, track.samples.front().t + 1.0, "gap"});
    gins::GeoWriteOptions options;
    RequireFiniteText([&](std::FILE* out) { gins::WriteGeodeticCsv(track, out); });
    RequireFiniteText([&](std::FILE* out) { gins::WriteKml(track, options, out); });
    RequireFiniteText([&](std::FILE* out) { gins::WriteGpx(track, options, out); });
    RequireFiniteText([&](std::FILE* out) { gins::WriteGeoJson(track, options, out); });
    RequireFiniteText([&](std::FILE* out) { gins::WriteNmea(track, gins::NmeaExportOptions{}, out); });
  } catch (const gins::InputError& e) {
    Require(std::strchr(e.what(), '\n') == nullptr);
  }
  std::remove(path.c_str());
  return 0;
}
