// One NMEA sentence (core/io/nmea_parse.h): the checksum rules, coordinates split exactly in the text, the
// fields of each sentence, and what is ignored rather than damaged.
#include "core/io/nmea_parse.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>

namespace gins {
namespace GINS_TEST_FILE {

std::string S(const std::string& body, bool lower = false) {
  unsigned x = 0;
  for (const char c : body) x ^= static_cast<unsigned char>(c);
  char hex[8];
  std::snprintf(hex, sizeof(hex), lower ? "*%02x" : "*%02X", x);
  return "$" + body + hex;
}

struct Parsed {
  const char* reason = nullptr;
  NmeaSentence s;
  std::string detail;
};

Parsed Parse(const std::string& line) {
  NmeaParser parser;
  Parsed p;
  p.reason = parser.Parse(line, &p.s, &p.detail);
  return p;
}

TEST(NmeaParse, ChecksumIsRequiredCheckedAndReadInEitherCase) {
  const std::string gga = "GPGGA,173021.75,4005.8029656,N,10508.8279915,W,4,15,0.7,1600.656,M,-16.288,M,1.0,0001";
  EXPECT_EQ(Parse(S(gga)).reason, nullptr);
  EXPECT_EQ(Parse(S(gga, true)).reason, nullptr);
  const Parsed bad = Parse("$" + gga + "*00");
  EXPECT_STREQ(bad.reason, "bad_checksum");
  EXPECT_EQ(bad.detail.rfind("checksum '00', the sentence's is ", 0), 0u) << bad.detail;
  EXPECT_STREQ(Parse("$" + gga).reason, "truncated");
  EXPECT_STREQ(Parse("$" + gga + "*5").reason, "truncated");
  EXPECT_STREQ(Parse(S(gga) + " tail").reason, "extra_fields");
  EXPECT_EQ(Parse(S(gga) + "  ").reason, nullptr);
  EXPECT_STREQ(Parse("no sentence here").reason, "not_nmea");
}

TEST(NmeaParse, GgaCoordinatesAreSplitInTheTextAndHeightIsAltitudePlusSeparation) {
  const Parsed p = Parse(S("GNGGA,000102.5,0030.5,S,00015.25,W,5,15,0.9,10.5,M,-2.25,M,,"));
  ASSERT_EQ(p.reason, nullptr) << p.detail;
  EXPECT_EQ(p.s.type, NmeaSentence::Type::kGga);
  EXPECT_TRUE(p.s.timed);
  EXPECT_EQ(p.s.sod, 62);
  EXPECT_EQ(p.s.frac, 0.5);
  EXPECT_EQ(p.s.lat, -(0.0 + 30.5 / 60.0));
  EXPECT_EQ(p.s.lon, -(0.0 + 15.25 / 60.0));
  EXPECT_EQ(p.s.height, 8.25);
  EXPECT_TRUE(p.s.has_separation);
  EXPECT_EQ(p.s.hdop, 0.9);
  EXPECT_EQ(p.s.quality, 5);
  for (const char* bad : {"GNGGA,000102.5,4060.0,N,10508.8,W,1,15,0.9,10.5,M,0,M,,",  // 60 minutes
                          "GNGGA,000102.5,40-5.8,N,10508.8,W,1,15,0.9,10.5,M,0,M,,",
                          "GNGGA,000102.5,4005.8,X,10508.8,W,1,15,0.9,10.5,M,0,M,,",  // hemisphere
                          "GNGGA,000102.5,4005.8,N,10508.8,W,1,15,0.9,abc,M,0,M,,"}) {
    EXPECT_NE(Parse(S(bad)).reason, nullptr) << bad;
  }
  EXPECT_STREQ(Parse(S("GNGGA,000102.5,,,,,1,15,0.9,10.5,M,0,M,,")).reason, "missing_fields");
}

TEST(NmeaParse, NoFixGgaAndSentencesWithoutATimeAreNotDamage) {
  const Parsed nofix = Parse(S("GNGGA,000102.5,,,,,0,00,99.99,,,,,,"));
  ASSERT_EQ(nofix.reason, nullptr);
  EXPECT_EQ(nofix.s.quality, 0);
  const Parsed untimed = Parse(S("GNGGA,,,,,,0,00,99.99,,,,,,"));
  ASSERT_EQ(untimed.reason, nullptr);
  EXPECT_EQ(untimed.s.ignored, "GGA without a time");
  EXPECT_EQ(Parse(S("GPGSA,A,3,10,23,,,,,,,,,,,1.8,1.0,1.5")).s.ignored, "sentence GSA");
}

TEST(NmeaParse, RmcVtgGstHdtThsAndZdaFields) {
  const Parsed rmc = Parse(S("GNRMC,173021.75,A,4005.8,N,10508.8,W,10.0,90.0,280825,,,D"));
  ASSERT_EQ(rmc.reason, nullptr);
  EXPECT_TRUE(rmc.s.has_date);
  EXPECT_EQ(rmc.s.days, 16671);
  EXPECT_TRUE(rmc.s.has_velocity);
  EXPECT_NEAR(rmc.s.v_enu.x(), 10.0 * 1852.0 / 3600.0, 1e-12);
  EXPECT_FALSE(Parse(S("GNRMC,173021.75,V,4005.8,N,10508.8,W,10.0,90.0,280825,,,N")).s.has_velocity);  // void
  EXPECT_FALSE(Parse(S("GNRMC,173021.75,A,4005.8,N,10508.8,W,10.0,90.0,280825,,,E")).s.has_velocity);  // DR
  const Parsed vtg = Parse(S("GPVTG,054.7,T,034.4,M,005.5,N,010.2,K"));  // NMEA 2.1: no mode field
  ASSERT_EQ(vtg.reason, nullptr);
  EXPECT_FALSE(vtg.s.timed);
  EXPECT_NEAR(vtg.s.speed, 10.2 / 3.6, 1e-12);
  const Parsed gst = Parse(S("GPGST,173021.75,0.5,0.03,0.02,0.0,0.012,0,0.025"));
  ASSERT_EQ(gst.reason, nullptr);
  EXPECT_EQ(gst.s.sigma_enu, Vec3(0.001, 0.012, 0.025));  // a 0 below the resolution is floored at 1 mm
  EXPECT_STREQ(Parse(S("GPGST,173021.75,0.5,0.03,0.02,0.0,-0.012,0.01,0.025")).reason, "absurd_value");
  EXPECT_EQ(Parse(S("GPHDT,271.5,T")).s.heading, 271.5);
  EXPECT_TRUE(Parse(S("GNTHS,271.5,A")).s.has_heading);
  EXPECT_FALSE(Parse(S("GNTHS,271.5,E")).s.has_heading);  // estimated: not a measured heading
  const Parsed zda = Parse(S("GPZDA,173021.75,28,08,2025,00,00"));
  ASSERT_EQ(zda.reason, nullptr);
  EXPECT_EQ(zda.s.days, 16671);
  EXPECT_STREQ(Parse(S("GPZDA,173021.75,30,02,2025,00,00")).reason, "bad_time");
}

}  // namespace
}  // namespace gins
