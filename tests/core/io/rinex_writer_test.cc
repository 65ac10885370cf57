// RINEX 3.04 observation writer (core/io/rinex_writer.h): every field read back by RinexObsReader, the
// calendar's carries, continuation lines of the type list, refused values, and no file without Commit.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/io/rinex.h"
#include "core/io/rinex_writer.h"
#include "test_util.h"

namespace gins {
namespace GINS_TEST_FILE {

bool Exists(const std::string& path) { return std::ifstream(path).good(); }

RinexObsHeader TestHeader() {
  RinexObsHeader h;
  h.obs_types[GnssSystem::kGps] = {"C1C", "L1C", "D1C", "S1C", "C2L", "L2L", "D2L", "S2L"};
  // 14 codes: a continuation line.
  h.obs_types[GnssSystem::kGalileo] = {"C1C", "L1C", "D1C", "S1C", "C5Q", "L5Q", "D5Q", "S5Q",
                                       "C7Q", "L7Q", "D7Q", "S7Q", "C8Q", "L8Q"};
  h.obs_types[GnssSystem::kBeidou] = {"C2I", "L2I", "D2I", "S2I"};
  h.has_approx_position = true;
  h.approx_position_ecef_m = {-1276969.0431, -4717225.3202, 4087226.6960};
  h.antenna_delta_hen_m = {1.2345, -0.5, 0.25};
  h.first_obs_gps_s = 1440437500.0001234;
  h.interval_s = 1.0;
  return h;
}

// Epochs with values on the format's 0.001 grid, every LLI/SSI, and missing observations.
std::vector<RinexObsEpoch> TestEpochs(const RinexObsHeader& h) {
  std::mt19937_64 rng(7);
  auto grid = [&](double lo, double hi) {
    const double u = static_cast<double>(rng() >> 11) * 0x1.0p-53;
    return std::round((lo + (hi - lo) * u) * 1000.0) / 1000.0;
  };
  std::vector<RinexObsEpoch> epochs;
  for (int k = 0; k < 5; ++k) {
    RinexObsEpoch e;
    e.gps_s = h.first_obs_gps_s + k;
    e.has_clock_offset = k % 2 == 0;
    e.receiver_clock_offset_s = e.has_clock_offset ? 1.234567890123e-4 * (k + 1) * (k == 2 ? -1 : 1) : 0.0;
    int prn = 1;
    for (const auto& [system, codes] : h.obs_types) {
      for (int s = 0; s < 3; ++s, prn += 3) {
        RinexSatelliteObs sat;
        sat.sat = {system, prn};
        for (size_t c = 0; c < codes.size(); ++c) {
          if ((c + s + k) % 5 == 3) continue;  // missing
          RinexObservation o;
          o.code = codes[c];
          o.value = codes[c][0] == 'L' ? grid(-9e8 + 1, 9.9e9) : codes[c][0] == 'D' ? grid(-5000, 5000)
                                                                                    : grid(1e7, 4e7);
          o.lli = static_cast<int>((c + k) % 8);
          o.ssi = static_cast<int>((c + s) % 10);
          sat.obs.push_back(o);
        }
        e.satellites.push_back(sat);
      }
    }
    epochs.push_back(e);
  }
  return epochs;
}

TEST(RinexWriter, RoundTripsThroughTheReader) {
  const std::string dir = test::MakeTempDir("rinex_writer");
  const std::string path = dir + "/obs.rnx";
  const RinexObsHeader h = TestHeader();
  const std::vector<RinexObsEpoch> epochs = TestEpochs(h);
  {
    RinexObsWriter w(path, h);
    for (const RinexObsEpoch& e : epochs) w.Add(e);
    w.Commit();
  }
  RinexObsReader r(path, InputOptions{});
  const RinexObsHeader& g = r.header();
  EXPECT_DOUBLE_EQ(g.version, 3.04);
  EXPECT_EQ(g.file_system, 'M');
  EXPECT_EQ(g.obs_types, h.obs_types);
  EXPECT_TRUE(g.has_approx_position);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(g.approx_position_ecef_m[i], h.approx_position_ecef_m[i], 5e-5);
    EXPECT_NEAR(g.antenna_delta_hen_m[i], h.antenna_delta_hen_m[i], 5e-5);
  }
  EXPECT_EQ(g.time_system, RinexTimeSystem::kGps);
  EXPECT_NEAR(g.first_obs_gps_s, h.first_obs_gps_s, 3e-7);  // 1e-7 s format, 2.4e-7 s double at 1.4e9
  EXPECT_EQ(g.interval_s, 1.0);
  RinexObsEpoch e;
  size_t n = 0;
  while (r.Next(&e)) {
    ASSERT_LT(n, epochs.size());
    const RinexObsEpoch& w = epochs[n++];
    EXPECT_NEAR(e.gps_s, w.gps_s, 3e-7);
    EXPECT_EQ(e.flag, 0);
    EXPECT_EQ(e.has_clock_offset, w.has_clock_offset);
    EXPECT_NEAR(e.receiver_clock_offset_s, w.receiver_clock_offset_s, 5e-13);
    ASSERT_EQ(e.satellites.size(), w.satellites.size());
    for (size_t s = 0; s < w.satellites.size(); ++s) {
      EXPECT_EQ(e.satellites[s].sat, w.satellites[s].sat);
      ASSERT_EQ(e.satellites[s].obs.size(), w.satellites[s].obs.size()) << w.satellites[s].sat.ToString();
      for (size_t o = 0; o < w.satellites[s].obs.size(); ++o) {
        const RinexObservation &a = e.satellites[s].obs[o], &b = w.satellites[s].obs[o];
        EXPECT_EQ(a.code, b.code);
        EXPECT_NEAR(a.value, b.value, 1e-6 * std::max(1.0, std::fabs(b.value) * 1e-9));  // on the grid
        EXPECT_EQ(a.lli, b.lli);
        EXPECT_EQ(a.ssi, b.ssi);
      }
    }
  }
  EXPECT_EQ(n, epochs.size());
  EXPECT_EQ(r.file().total_skipped(), 0u);
}

TEST(RinexWriter, ValuesOffTheGridRoundToTheFormat) {
  RinexObsHeader h = TestHeader();
  RinexObsEpoch e;
  e.gps_s = h.first_obs_gps_s;
  RinexSatelliteObs s;
  s.sat = {GnssSystem::kGps, 7};
  s.obs.push_back({"C1C", 21234567.12349, 0, 0});
  s.obs.push_back({"L1C", -1234.56751, 1, 9});
  e.satellites.push_back(s);
  const std::string text = FormatRinexObsEpoch(h, e);
  EXPECT_NE(text.find("\nG07  21234567.123       -1234.56819\n"), std::string::npos) << text;
  e.gps_s = 1440437500.125;  // exact in a double
  EXPECT_EQ(FormatRinexObsEpoch(h, e).substr(0, 36), "> 2025 08 28 17 31 40.1250000  0  1\n");
}

TEST(RinexWriter, CalendarCarriesAtTheEpochResolution) {
  const RinexCalendar c = GpsSecondsToCalendar(1440437459.99999996);  // 17:30:59.99999996 → 17:31:00
  EXPECT_EQ(c.minute, 31);
  EXPECT_EQ(c.second, 0.0);
  const RinexCalendar d = GpsSecondsToCalendar(0.0);
  EXPECT_EQ(d.year, 1980);
  EXPECT_EQ(d.month, 1);
  EXPECT_EQ(d.day, 6);
  const RinexCalendar leap = GpsSecondsToCalendar(1234567890.0);
  std::string why;
  double back = 0.0;
  ASSERT_TRUE(RinexToGpsSeconds(leap, RinexTimeSystem::kGps, -1, &back, &why)) << why;
  EXPECT_EQ(back, 1234567890.0);
  // Every day of four years, leap days included, through the reader's inverse.
  for (int day = 0; day < 4 * 366; ++day) {
    const double t = 1.3e9 + 86400.0 * day + 3723.5;
    ASSERT_TRUE(RinexToGpsSeconds(GpsSecondsToCalendar(t), RinexTimeSystem::kGps, -1, &back, &why)) << why;
    ASSERT_EQ(back, t) << day;
  }
}

TEST(RinexWriter, RefusesWhatTheFormatCannotHold) {
  const RinexObsHeader h = TestHeader();
  RinexObsEpoch e;
  e.gps_s = h.first_obs_gps_s;
  RinexSatelliteObs s;
  s.sat = {GnssSystem::kGps, 7};
  s.obs.push_back({"C1C", 1e10, 0, 0});
  e.satellites = {s};
  EXPECT_THROW(FormatRinexObsEpoch(h, e), std::invalid_argument);
  e.satellites[0].obs[0] = {"C5Q", 1.0, 0, 0};  // not a GPS code of the header
  EXPECT_THROW(FormatRinexObsEpoch(h, e), std::invalid_argument);
  e.satellites[0].obs[0] = {"C1C", 1.0, 8, 0};
  EXPECT_THROW(FormatRinexObsEpoch(h, e), std::invalid_argument);
  e.satellites[0] = s;
  e.satellites[0].sat = {GnssSystem::kGlonass, 1};
  e.satellites[0].obs[0] = {"C1C", 1.0, 0, 0};
  EXPECT_THROW(FormatRinexObsEpoch(h, e), std::invalid_argument);
  RinexObsHeader utc = h;
  utc.time_system = RinexTimeSystem::kUtc;
  EXPECT_THROW(FormatRinexObsHeader(utc), std::invalid_argument);
}

TEST(RinexWriter, NoFileWithoutCommit) {
  const std::string path = test::MakeTempDir("rinex_writer") + "/obs.rnx";
  const RinexObsHeader h = TestHeader();
  {
    RinexObsWriter w(path, h);
    w.Add(TestEpochs(h)[0]);
  }
  EXPECT_FALSE(Exists(path));
  {
    RinexObsWriter w(path, h);
    w.Commit();
  }
  EXPECT_TRUE(Exists(path));
}

}  // namespace
}  // namespace gins
