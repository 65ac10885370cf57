// libFuzzer target: the RINEX 3 readers (core/io/rinex.h) on an arbitrary file (plain or gzip), as an
// observation file and as a navigation file, each under both damage policies and a small line-length
// limit. Checks: no crash, no hang, only InputError escapes and its message is one line; epochs come in
// strictly increasing time with finite values, satellites of a system the header declares, and the counts
// add up; every ephemeris is finite.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

#include "core/io/rinex.h"
#include "fuzz/fuzz_file.h"

namespace {

using gins::fuzz::Require;

void ReadObs(const std::string& path, const gins::InputOptions& options) {
  try {
    gins::RinexObsReader reader(path, options);
    const gins::RinexObsHeader& h = reader.header();
    Require(h.version >= 3.0 && h.version < 4.0 && !h.obs_types.empty() && std::isfinite(h.first_obs_gps_s));
    gins::RinexObsEpoch e;
    double last = -1e300;
    uint64_t epochs = 0, satellites = 0;
    while (reader.Next(&e)) {
      Require(std::isfinite(e.gps_s) && e.gps_s > last && (e.flag == 0 || e.flag == 1));
      Require(std::isfinite(e.receiver_clock_offset_s));
      last = e.gps_s;
      for (const gins::RinexSatelliteObs& s : e.satellites) {
        Require(h.obs_types.count(s.sat.system) == 1);
        for (const gins::RinexObservation& o : s.obs) {
          Require(std::isfinite(o.value) && o.code.size() == 3 && o.lli >= 0 && o.lli <= 7 && o.ssi >= 0 &&
                  o.ssi <= 9);
        }
      }
      ++epochs;
      satellites += e.satellites.size();
    }
    Require(reader.stats().epochs == epochs && reader.stats().satellite_records == satellites);
    Require(reader.file().total_skipped() <= reader.file().lines + 1);  // +1: a gzip error after the last line
  } catch (const gins::InputError& e) {
    Require(std::string(e.what()).find('\n') == std::string::npos);
  }
}

void ReadNav(const std::string& path, const gins::InputOptions& options) {
  try {
    const gins::RinexNav nav = gins::ReadRinexNav(path, options);
    uint64_t records = 0;
    for (const auto& [system, n] : nav.records) records += n;
    Require(records == nav.kepler.size() + nav.state.size());
    for (const gins::KeplerEphemeris& k : nav.kepler) {
      Require(std::isfinite(k.toc_gps_s) && std::isfinite(k.af0_s) && std::isfinite(k.sqrt_a_sqrt_m) &&
              std::isfinite(k.e) && std::isfinite(k.toe_gps_s()));
    }
    for (const gins::StateVectorEphemeris& s : nav.state) {
      Require(std::isfinite(s.toc_gps_s) && std::isfinite(s.position_km[0]) && std::isfinite(s.clock_bias_s));
    }
    Require(nav.file.total_skipped() <= nav.file.lines + 1);
  } catch (const gins::InputError& e) {
    Require(std::string(e.what()).find('\n') == std::string::npos);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = gins::fuzz::WriteInput("rinex", data, size);
  if (path.empty()) return 0;
  gins::InputOptions skip;
  skip.max_line_length = 300;  // small enough for the fuzzer to reach line_too_long
  skip.max_errors = 50;
  gins::InputOptions stop = skip;
  stop.on_error = gins::InputErrorPolicy::kStop;
  for (const gins::InputOptions& options : {skip, stop}) {
    ReadObs(path, options);
    ReadNav(path, options);
  }
  std::remove(path.c_str());
  return 0;
}
