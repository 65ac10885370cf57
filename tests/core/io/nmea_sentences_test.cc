#include "core/io/nmea_sentences.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace gins {
namespace GINS_TEST_FILE {

// 2025-08-28 17:30:22.25 UTC (GPS second 1440437440.25).
constexpr double kKnownUtc = 1756402222.25;

NmeaEpoch KnownEpoch() {
  NmeaEpoch e;
  e.unix_utc = kKnownUtc;
  e.sample.lat_deg = 30.52781234;   // 30° 31.6687404'
  e.sample.lon_deg = 114.35567891;  // 114° 21.3407346'
  e.sample.height_m = 23.45678;
  e.sample.v_enu = Vec3(3.0, 4.0, 0.1);  // 5 m/s = 9.719 kn towards 36.870°
  e.sample.heading_deg = 37.5;
  e.sample.sigma_enu = Vec3(0.012, 0.034, 0.056);
  e.quality = NmeaQuality::kRtkFixed;
  return e;
}

// The checksum again, apart from the code under test.
std::string XorHex(const std::string& body) {
  int x = 0;
  for (char ch : body) x ^= ch;
  const char* digits = "0123456789ABCDEF";
  return {digits[x >> 4], digits[x & 15]};
}

// The comma-separated fields after "$GNxxx," of a sentence whose frame and checksum check.
std::vector<std::string> Fields(const std::string& sentence) {
  EXPECT_GE(sentence.size(), 10u);
  EXPECT_EQ(sentence.front(), '$');
  EXPECT_EQ(sentence.substr(sentence.size() - 2), "\r\n");
  const size_t star = sentence.find('*');
  EXPECT_EQ(star, sentence.size() - 5);
  const std::string body = sentence.substr(1, star - 1);
  EXPECT_EQ(sentence.substr(star + 1, 2), XorHex(body));
  std::vector<std::string> fields;
  size_t begin = body.find(',') + 1;
  for (size_t comma; (comma = body.find(',', begin)) != std::string::npos; begin = comma + 1) {
    fields.push_back(body.substr(begin, comma - begin));
  }
  fields.push_back(body.substr(begin));
  return fields;
}

TEST(NmeaSentences, ChecksumIsTheXorBetweenDollarAndStar) {
  // The classic GGA example of the NMEA references, "*47".
  EXPECT_EQ(NmeaChecksum("GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,"), "47");
  EXPECT_EQ(NmeaChecksum(""), "00");
  EXPECT_EQ(NmeaChecksum("\x0a"), "0A");  // upper-case, two digits
}

TEST(NmeaSentences, GgaOfAKnownEpoch) {
  const std::string body = "GNGGA,173022.25,3031.6687404,N,11421.3407346,E,4,,,23.4568,M,0.0,M,,";
  EXPECT_EQ(XorHex(body), "6D");
  EXPECT_EQ(NmeaGga(KnownEpoch()), "$" + body + "*6D\r\n");
  EXPECT_EQ(Fields(NmeaGga(KnownEpoch())).size(), 14u);
}

TEST(NmeaSentences, RmcOfAKnownEpoch) {
  const std::string body = "GNRMC,173022.25,A,3031.6687404,N,11421.3407346,E,9.719,36.870,280825,,,D";
  EXPECT_EQ(XorHex(body), "76");
  EXPECT_EQ(NmeaRmc(KnownEpoch()), "$" + body + "*76\r\n");
}

TEST(NmeaSentences, TalkerIsTheCallers) {
  NmeaEpoch e = KnownEpoch();
  e.talker = "GP";
  EXPECT_EQ(NmeaGga(e).substr(0, 7), "$GPGGA,");
  EXPECT_EQ(NmeaHdt(e).substr(0, 7), "$GPHDT,");
}

TEST(NmeaSentences, TimeRoundingCarriesIntoTheMinuteHourAndDay) {
  NmeaEpoch e = KnownEpoch();
  e.unix_utc = kKnownUtc - 22.25 + 37.996;  // 17:30:37.996
  EXPECT_EQ(Fields(NmeaGga(e))[0], "173038.00");
  e.unix_utc = kKnownUtc - 22.25 + 59.996;  // 17:30:59.996
  EXPECT_EQ(Fields(NmeaGga(e))[0], "173100.00");
  e.unix_utc = kKnownUtc + 29 * 60 + 37.746;  // 17:59:59.996
  EXPECT_EQ(Fields(NmeaGst(e))[0], "180000.00");
  e.unix_utc = kKnownUtc + 29 * 60 + 37.744;  // 17:59:59.994
  EXPECT_EQ(Fields(NmeaGga(e))[0], "175959.99");

  // 2016-12-31 23:59:59.996: the rounded time is on the next day, and so is the RMC's date.
  e.unix_utc = 1483228800.0 - 0.004;
  const std::vector<std::string> rmc = Fields(NmeaRmc(e));
  EXPECT_EQ(rmc[0], "000000.00");
  EXPECT_EQ(rmc[8], "010117");
  e.unix_utc = 1483228800.0 - 0.006;
  EXPECT_EQ(Fields(NmeaRmc(e))[0], "235959.99");
  EXPECT_EQ(Fields(NmeaRmc(e))[8], "311216");
}

TEST(NmeaSentences, RmcDateOfALeapDay) {
  NmeaEpoch e = KnownEpoch();
  e.unix_utc = 1709164800.5;  // 2024-02-29 00:00:00.50
  const std::vector<std::string> rmc = Fields(NmeaRmc(e));
  EXPECT_EQ(rmc[0], "000000.50");
  EXPECT_EQ(rmc[8], "290224");
}

TEST(NmeaSentences, GgaCarriesTheMinuteRoundingIntoTheDegree) {
  NmeaEpoch e = KnownEpoch();
  e.sample.lat_deg = 12.0 + 59.99999999 / 60.0;
  e.sample.lon_deg = -(7.0 + 59.99999999 / 60.0);
  std::vector<std::string> gga = Fields(NmeaGga(e));
  EXPECT_EQ(gga[1], "1300.0000000");
  EXPECT_EQ(gga[3], "00800.0000000");
  EXPECT_EQ(gga[4], "W");
  // Up to the last degree of longitude.
  e.sample.lat_deg = 89.9999999;
  e.sample.lon_deg = -(179.0 + 59.99999999 / 60.0);
  gga = Fields(NmeaGga(e));
  EXPECT_EQ(gga[1], "8959.9999940");
  EXPECT_EQ(gga[3], "18000.0000000");
  EXPECT_EQ(gga[4], "W");
  // Just below the carry, the 7th decimal is kept.
  e.sample.lat_deg = 12.0 + 59.9999999 / 60.0;
  EXPECT_EQ(Fields(NmeaGga(e))[1], "1259.9999999");
}

TEST(NmeaSentences, HemispheresAndZeroPaddedDegrees) {
  NmeaEpoch e = KnownEpoch();
  e.sample.lat_deg = -33.86881234;
  e.sample.lon_deg = -151.20931234;
  std::vector<std::string> gga = Fields(NmeaGga(e));
  EXPECT_EQ(gga[1] + gga[2] + gga[3] + gga[4], "3352.1287404S15112.5587404W");
  e.sample.lat_deg = 5.5;
  e.sample.lon_deg = 7.25;
  gga = Fields(NmeaGga(e));
  EXPECT_EQ(gga[1] + gga[2] + gga[3] + gga[4], "0530.0000000N00715.0000000E");
  // The equator and the prime meridian, and what rounds onto them from the south and west, are N and E.
  e.sample.lat_deg = -1e-12;
  e.sample.lon_deg = -1e-12;
  gga = Fields(NmeaGga(e));
  EXPECT_EQ(gga[1] + gga[2] + gga[3] + gga[4], "0000.0000000N00000.0000000E");
  // A longitude past the antimeridian is wrapped.
  e.sample.lon_deg = 190.5;
  gga = Fields(NmeaGga(e));
  EXPECT_EQ(gga[3] + gga[4], "16930.0000000W");
}

TEST(NmeaSentences, NegativeHeightAndNoMinusZero) {
  NmeaEpoch e = KnownEpoch();
  e.sample.height_m = -12.34567;
  EXPECT_EQ(Fields(NmeaGga(e))[8], "-12.3457");
  e.sample.height_m = -0.00004;
  EXPECT_EQ(Fields(NmeaGga(e))[8], "0.0000");
}

TEST(NmeaSentences, QualityAndModeIndicator) {
  NmeaEpoch e = KnownEpoch();
  const std::pair<NmeaQuality, const char*> cases[] = {{NmeaQuality::kGps, "A"},
                                                       {NmeaQuality::kDgps, "D"},
                                                       {NmeaQuality::kRtkFixed, "D"},
                                                       {NmeaQuality::kRtkFloat, "D"},
                                                       {NmeaQuality::kDeadReckoning, "E"}};
  for (const auto& [quality, mode] : cases) {
    e.quality = quality;
    EXPECT_EQ(Fields(NmeaGga(e))[5], std::to_string(static_cast<int>(quality)));
    const std::vector<std::string> rmc = Fields(NmeaRmc(e));
    EXPECT_EQ(rmc[1], "A");
    EXPECT_EQ(rmc[11], mode);
  }
}

TEST(NmeaSentences, DeadReckoningWithoutVelocityHasEmptySpeedAndCourse) {
  NmeaEpoch e = KnownEpoch();
  e.quality = NmeaQuality::kDeadReckoning;
  e.sample.v_enu.reset();
  const std::vector<std::string> rmc = Fields(NmeaRmc(e));
  ASSERT_EQ(rmc.size(), 12u);
  EXPECT_EQ(rmc[6], "");
  EXPECT_EQ(rmc[7], "");
  EXPECT_EQ(rmc[11], "E");
  EXPECT_EQ(Fields(NmeaGga(e))[5], "6");
}

TEST(NmeaSentences, CourseIsEmptyBelowFiveCentimetresPerSecond) {
  NmeaEpoch e = KnownEpoch();
  e.sample.v_enu = Vec3(0.03, 0.03, 2.0);  // 0.042 m/s horizontally: the vertical part does not count
  std::vector<std::string> rmc = Fields(NmeaRmc(e));
  EXPECT_EQ(rmc[6], "0.082");
  EXPECT_EQ(rmc[7], "");
  e.sample.v_enu = Vec3(-1.5, 0.0, 0.0);  // west
  rmc = Fields(NmeaRmc(e));
  EXPECT_EQ(rmc[6], "2.916");
  EXPECT_EQ(rmc[7], "270.000");
  e.sample.v_enu = Vec3(-1e-6, 10.0, 0.0);  // 359.99999° rounds to 0, not 360
  EXPECT_EQ(Fields(NmeaRmc(e))[7], "0.000");
}

TEST(NmeaSentences, GstSigmasAndTheAxisAlignedEllipse) {
  NmeaEpoch e = KnownEpoch();  // σ east 0.012, north 0.034, up 0.056
  EXPECT_EQ(NmeaGst(e), "$GNGST,173022.25,,0.0340,0.0120,0.0,0.0340,0.0120,0.0560*" +
                            XorHex("GNGST,173022.25,,0.0340,0.0120,0.0,0.0340,0.0120,0.0560") + "\r\n");
  e.sample.sigma_enu = Vec3(0.5, 0.25, 1.0);  // wider east: the semi-major axis points east
  const std::vector<std::string> gst = Fields(NmeaGst(e));
  ASSERT_EQ(gst.size(), 8u);
  EXPECT_EQ(gst[1], "");
  EXPECT_EQ(gst[2], "0.5000");
  EXPECT_EQ(gst[3], "0.2500");
  EXPECT_EQ(gst[4], "90.0");
  EXPECT_EQ(gst[5], "0.2500");
  EXPECT_EQ(gst[6], "0.5000");
  EXPECT_EQ(gst[7], "1.0000");
  e.sample.sigma_enu.reset();
  EXPECT_EQ(NmeaGst(e), "");
}

TEST(NmeaSentences, HdtIsTheTrueHeadingInZeroTo360) {
  NmeaEpoch e = KnownEpoch();
  EXPECT_EQ(NmeaHdt(e), "$GNHDT,37.500,T*" + XorHex("GNHDT,37.500,T") + "\r\n");
  e.sample.heading_deg = -90.0;
  EXPECT_EQ(Fields(NmeaHdt(e))[0], "270.000");
  e.sample.heading_deg = 359.9996;
  EXPECT_EQ(Fields(NmeaHdt(e))[0], "0.000");
  e.sample.heading_deg = 725.25;
  EXPECT_EQ(Fields(NmeaHdt(e))[0], "5.250");
  e.sample.heading_deg.reset();
  EXPECT_EQ(NmeaHdt(e), "");
}

// NMEA's limit is 82 characters with the '$' and the CR LF; the 7-decimal minutes leave room for it.
TEST(NmeaSentences, TheLongestSentencesFitEightyTwoCharacters) {
  NmeaEpoch e = KnownEpoch();
  e.unix_utc = 1483228800.0 - 0.01;  // 23:59:59.99
  e.sample.lat_deg = -89.99999999;
  e.sample.lon_deg = -179.9999999;
  e.sample.height_m = -1234.56789;
  e.sample.v_enu = Vec3(-0.02, 514.0, 0.0);  // 999.1 kn, course 359.998
  e.sample.heading_deg = 359.9994;
  e.sample.sigma_enu = Vec3(999.0, 9999.0, 99999.0);
  EXPECT_EQ(NmeaGga(e).size(), 77u);
  EXPECT_EQ(NmeaRmc(e).size(), 81u);
  EXPECT_LE(NmeaGst(e).size(), 82u);
  EXPECT_LE(NmeaHdt(e).size(), 82u);
}

TEST(NmeaSentences, NothingIsWrittenWithANumberThatIsNotFinite) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  NmeaEpoch e = KnownEpoch();
  e.sample.lat_deg = nan;
  EXPECT_EQ(NmeaGga(e), "");
  EXPECT_EQ(NmeaRmc(e), "");
  EXPECT_EQ(NmeaGst(e), "");
  EXPECT_EQ(NmeaHdt(e), "");
  e = KnownEpoch();
  e.unix_utc = std::numeric_limits<double>::infinity();
  EXPECT_EQ(NmeaRmc(e), "");
  // A velocity, σ or heading that is not finite is absent.
  e = KnownEpoch();
  e.sample.v_enu = Vec3(nan, 1.0, 0.0);
  e.sample.sigma_enu = Vec3(0.1, nan, 0.1);
  e.sample.heading_deg = nan;
  EXPECT_EQ(Fields(NmeaRmc(e))[6], "");
  EXPECT_EQ(NmeaGst(e), "");
  EXPECT_EQ(NmeaHdt(e), "");
}

}  // namespace
}  // namespace gins
