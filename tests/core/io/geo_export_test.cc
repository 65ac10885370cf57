// `gins export`'s conversions (core/io/geo_export.h): each kind of input read back as the same track, the
// geodetic CSV and TUM-in-a-frame round trips, the NMEA grid and quality, and damaged geodetic CSVs refused
// with their line.
#include "core/io/geo_export.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "core/io/log_reader.h"
#include "core/io/trajectory_writer.h"
#include "core/so3.h"
#include "test_util.h"

namespace gins {
namespace GINS_TEST_FILE {

const GeodeticPoint kOrigin{31.5, 120.4, 10.0};

NavState StateAt(int k) {
  NavState x;
  x.t = 1400000000.0 + 0.1 * k;
  x.p_wb = Vec3(300.0 + 2.0 * k, -150.0 + k, 0.5 * k);
  x.v_w = Vec3(20.0, 10.0, 5.0);
  // Body x axis 30° north of east: a heading of 60° from north.
  x.q_wb = QuatFromYaw(30.0 * M_PI / 180.0);
  return x;
}

std::string WriteRun(const std::string& dir, int n) {
  TumWriter tum(dir + "/eskf.tum", "eskf", kOrigin);
  StatesCsvWriter csv(dir + "/eskf_states.csv");
  for (int k = 0; k < n; ++k) {
    tum.AddWithStates(&csv, nullptr, StateAt(k), Vec3(0.01, 0.02, 0.03), Vec3::Constant(0.1), Vec3::Constant(0.01), 1.0);
  }
  tum.Commit();
  csv.Commit();
  return dir + "/eskf_states.csv";
}

std::string ToText(const std::function<void(std::FILE*)>& write) {
  char* buf = nullptr;
  size_t size = 0;
  std::FILE* f = open_memstream(&buf, &size);
  write(f);
  std::fclose(f);
  std::string text(buf, size);
  std::free(buf);
  return text;
}

TEST(GeoExport, AStatesCsvBecomesGeodeticPointsWithLocalVelocityHeadingAndSigma) {
  const std::string dir = test::MakeTempDir("geo_export_states");
  const ExportSource src = ReadExportSource(WriteRun(dir, 5), std::nullopt);
  EXPECT_EQ(src.kind, "states");
  const GeoTrack track = ToGeoTrack(src, "eskf");
  ASSERT_EQ(track.samples.size(), 5u);
  const LocalEnuFrame frame(kOrigin);
  for (int k = 0; k < 5; ++k) {
    const GeoSample& g = track.samples[k];
    EXPECT_LT((frame.ToEnu({g.lat_deg, g.lon_deg, g.height_m}) - StateAt(k).p_wb).norm(), 2e-5);
    ASSERT_TRUE(g.v_enu && g.heading_deg && g.sigma_enu);
    // 335 m from the origin the local north turns by about 0.002° against the frame's.
    EXPECT_NEAR(*g.heading_deg, 60.0, 0.01);
    EXPECT_NEAR(g.v_enu->norm(), StateAt(k).v_w.norm(), 1e-4);
    EXPECT_NEAR(g.v_enu->x(), 20.0, 0.01);
    EXPECT_NEAR(g.sigma_enu->y(), 0.02, 1e-6);
  }
}

TEST(GeoExport, TheGeodeticCsvReadsBackAsTheSameTrack) {
  const std::string dir = test::MakeTempDir("geo_export_lla");
  const GeoTrack track = ToGeoTrack(ReadExportSource(WriteRun(dir, 4), std::nullopt), "eskf");
  test::WriteFile(dir + "/eskf_lla.csv", ToText([&](std::FILE* f) { WriteGeodeticCsv(track, f); }));
  const ExportSource back = ReadExportSource(dir + "/eskf_lla.csv", std::nullopt);
  EXPECT_EQ(back.kind, "lla");
  EXPECT_FALSE(back.has_attitude);
  const GeoTrack again = ToGeoTrack(back, "eskf");
  ASSERT_EQ(again.samples.size(), track.samples.size());
  for (size_t i = 0; i < track.samples.size(); ++i) {
    EXPECT_NEAR(again.samples[i].lat_deg, track.samples[i].lat_deg, 1e-9);
    EXPECT_NEAR(again.samples[i].lon_deg, track.samples[i].lon_deg, 1e-9);
    EXPECT_NEAR(again.samples[i].height_m, track.samples[i].height_m, 1e-4);
    EXPECT_FALSE(again.samples[i].heading_deg.has_value());
    ASSERT_TRUE(again.samples[i].sigma_enu.has_value());
    EXPECT_NEAR(again.samples[i].sigma_enu->z(), 0.03, 1e-6);
  }
  std::FILE* sink = std::fopen("/dev/null", "w");
  EXPECT_THROW(WriteTumInFrame(back, kOrigin, sink), InputError);  // no attitude for a TUM file
  std::fclose(sink);
}

TEST(GeoExport, ATruthWrittenAsTumInAnotherFrameKeepsItsPoints) {
  const std::string dir = test::MakeTempDir("geo_export_truth");
  const std::string truth = dir + "/truth.csv";
  test::WriteFile(truth,
                  "t,lat,lon,alt,qw,qx,qy,qz,ve,vn,vu\n"
                  "1400000000.0,31.501,120.402,12.0,0.923879533,0,0,0.382683432,1,2,0\n"
                  "1400000001.0,31.502,120.403,13.0,0.923879533,0,0,0.382683432,1,2,0\n");
  const ExportSource src = ReadExportSource(truth, std::nullopt);
  EXPECT_EQ(src.kind, "truth");
  const std::string text = ToText([&](std::FILE* f) { WriteTumInFrame(src, kOrigin, f); });
  const std::string tum = dir + "/truth.tum";
  test::WriteFile(tum, text);
  const Trajectory t = ReadTrajectory(tum);
  ASSERT_TRUE(t.origin.has_value());
  EXPECT_NEAR(t.origin->lat_deg, kOrigin.lat_deg, 1e-10);
  ASSERT_EQ(t.samples.size(), 2u);
  const LocalEnuFrame frame(kOrigin);
  EXPECT_LT((t.samples[1].p_w - frame.ToEnu({31.502, 120.403, 13.0})).norm(), 2e-5);
  // The 45° yaw of the local ENU frame there, give or take its meridian convergence.
  const GeoTrack g = ToGeoTrack(src, "truth");
  EXPECT_NEAR(*g.samples[0].heading_deg, 45.0, 1e-6);
}

TEST(GeoExport, NmeaEpochsFollowTheGridAndQualityTheSigmaAndOutages) {
  double next = -1e300;
  std::vector<double> kept;
  for (double t = 100.0; t < 103.0; t += 0.25) {
    if (OnNmeaGrid(t, 1.0, &next)) kept.push_back(t);
  }
  EXPECT_EQ(kept, (std::vector<double>{100.0, 101.0, 102.0}));
  next = -1e300;
  kept.clear();
  for (double t : {100.3, 100.9, 101.1, 103.7}) {
    if (OnNmeaGrid(t, 1.0, &next)) kept.push_back(t);
  }
  EXPECT_EQ(kept, (std::vector<double>{100.3, 101.1, 103.7}));
  GeoSample s;
  s.t = 50.0;
  EXPECT_EQ(QualityOf({}, s), NmeaQuality::kGps);
  s.sigma_enu = Vec3(0.02, 0.03, 0.05);
  EXPECT_EQ(QualityOf({}, s), NmeaQuality::kRtkFixed);
  s.sigma_enu = Vec3(0.2, 0.3, 0.5);
  EXPECT_EQ(QualityOf({}, s), NmeaQuality::kRtkFloat);
  s.sigma_enu = Vec3(2.0, 3.0, 5.0);
  EXPECT_EQ(QualityOf({}, s), NmeaQuality::kGps);
  EXPECT_EQ(QualityOf({{40.0, 60.0, "outage"}}, s), NmeaQuality::kDeadReckoning);
  GeoTrack relative;
  relative.samples.push_back(s);  // t = 50 s: not an absolute time
  std::FILE* sink = std::fopen("/dev/null", "w");
  EXPECT_THROW(WriteNmea(relative, NmeaExportOptions{}, sink), InputError);
  GeoTrack beyond;  // past the log's 1e10 s limit (found by the export_source fuzzer: no date to write)
  s.t = 1400000000.0;
  beyond.samples.push_back(s);
  s.t = 2e130;
  beyond.samples.push_back(s);
  EXPECT_THROW(WriteNmea(beyond, NmeaExportOptions{}, sink), InputError);
  std::fclose(sink);
}

TEST(GeoExport, DamagedGeodeticCsvsAreRefusedWithTheirLine) {
  const std::string dir = test::MakeTempDir("geo_export_damaged");
  const std::string header = "t,lat_deg,lon_deg,height_m,sigma_e_m,sigma_n_m,sigma_u_m\n";
  const std::string good = "1.0,31.5,120.4,10.0,0.1,0.1,0.2\n";
  struct Case {
    std::string rows, expected;
  };
  for (const Case& c : std::vector<Case>{
           {good + "2.0,31.5,120.4,10.0,0.1,0.1\n", ":3: expected 7 numbers"},
           {good + "2.0,31.5,abc,10.0,0.1,0.1,0.2\n", ":3: expected 7 numbers"},
           {good + "2.0,31.5,120.4,10.0,0.1,0.1,0.2,9\n", ":3: expected 7 numbers"},
           {good + "0.5,31.5,120.4,10.0,0.1,0.1,0.2\n", ":3: time does not increase"},
           {good + "2.0,95.0,120.4,10.0,0.1,0.1,0.2\n", ":3: latitude, longitude or height out of range"},
           {good + "2.0,31.5,120.4,nan,0.1,0.1,0.2\n", ":3: expected 7 numbers"},
           {"", ": no rows"},
       }) {
    const std::string path = dir + "/x_lla.csv";
    test::WriteFile(path, header + c.rows);
    try {
      ReadExportSource(path, std::nullopt);
      ADD_FAILURE() << "accepted: " << c.rows;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(path + c.expected), std::string::npos) << e.what();
    }
  }
}

TEST(GeoExport, AForeignTumNeedsAnOrigin) {
  const std::string dir = test::MakeTempDir("geo_export_foreign");
  test::WriteFile(dir + "/evo.tum", "1.0 0 0 0 0 0 0 1\n2.0 1 0 0 0 0 0 1\n");
  EXPECT_THROW(ReadExportSource(dir + "/evo.tum", std::nullopt), InputError);
  const ExportSource src = ReadExportSource(dir + "/evo.tum", kOrigin);
  EXPECT_EQ(src.kind, "tum");
  const GeoTrack g = ToGeoTrack(src, "evo");
  EXPECT_NEAR(g.samples[0].lat_deg, kOrigin.lat_deg, 1e-9);
  EXPECT_FALSE(g.samples[0].v_enu.has_value());
}

}  // namespace
}  // namespace gins
