// Raw GNSS observations from RINEX 3 files beside a log (raw_gnss.obs_file, raw_gnss.nav_file; `gins run
// --obs --nav`): the navigation file read whole, the observation file streamed one epoch ahead, and each
// epoch's signals picked for the estimators (core/gnss_raw.h). The estimator pipeline merges the epochs into
// the log's stream by time: the log's time must be GPS seconds (RINEX epochs are receiver time, GPS).
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/gnss_raw.h"
#include "core/io/rinex.h"

namespace gins {

// The models' options for a navigation file: mask, σ, the ionosphere (raw_gnss.ionosphere; auto takes the
// ionosphere-free combination where a satellite has two codes, else Klobuchar where the header has GPSA and
// GPSB, else none with its σ).
RawGnssNav MakeRawGnssNav(const RinexNav& nav, const GnssRawOptions& options);

// Each satellite's signals of an epoch: per system the first code of its list present, and for the
// ionosphere-free combination (nav.spp.ionosphere) the first of a second list:
//   GPS      C1C                 | C2W C2L C5Q C5X
//   Galileo  C1C C1X             | F/NAV clock: C5Q C5X; I/NAV: C7Q C7X (the clock's own pair)
//   BeiDou   C2I C6I C1P C1X     | C6I C7I (never the first's own)
// BeiDou's B3I (C6I) has no group delay in D1/D2 (it is their reference) and B1C (C1P) an unknown one, so
// B1I, then B3I, come before B1C. Systems without broadcast Keplerian orbits here (GLONASS, SBAS) are left
// out. The Doppler (nav.use_doppler) and C/N0 are the first code's (D1C, S1C for C1C).
std::vector<RawGnssObservation> SelectSignals(const std::vector<RinexSatelliteObs>& satellites, const RawGnssNav& nav);

class RawGnssFeed {
 public:
  // Reads the navigation file and the observation file's header; InputError (naming the file) if either
  // cannot be read. `input`: the damage policy for both.
  RawGnssFeed(const GnssRawOptions& options, const InputOptions& input);
  ~RawGnssFeed();

  // The next epoch if its tag is at or before t (GPS seconds); false otherwise or at the end.
  bool NextBefore(double t, RawGnssMeasurement* m);
  // Tag of the next epoch (nullopt at the end).
  std::optional<double> PeekTime();

  nlohmann::json Stats() const;

 private:
  bool Fill();
  RinexObsReader reader_;
  std::shared_ptr<const RawGnssNav> nav_;
  RinexNav nav_file_stats_;  // the navigation file's counts (its records moved into nav_)
  std::optional<RinexObsEpoch> next_;
  bool ended_ = false;
  uint64_t epochs_ = 0, satellites_ = 0, without_signal_ = 0;
};

}  // namespace gins
