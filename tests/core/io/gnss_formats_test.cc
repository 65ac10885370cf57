// The quality classes and σ policy shared by the GNSS formats (core/io/gnss_formats.h, gnss_formats.cc).
#include "core/io/gnss_formats.h"

#include <gtest/gtest.h>

#include <string>

#include "core/io/nmea_parse.h"

namespace gins {
namespace GINS_TEST_FILE {

TEST(GnssFormats, QualityNamesRoundTripInBestFirstOrder) {
  const char* names[] = {"fix", "float", "ppp", "dgps", "sbas", "single"};
  for (int i = 0; i < kNumFixQualities; ++i) {
    FixQuality q = FixQuality::kSingle;
    ASSERT_TRUE(ParseFixQuality(names[i], &q)) << names[i];
    EXPECT_EQ(static_cast<int>(q), i);
    EXPECT_STREQ(FixQualityName(q), names[i]);
  }
  FixQuality q;
  EXPECT_FALSE(ParseFixQuality("rtk", &q));
  EXPECT_LT(FixQuality::kFix, FixQuality::kFloat);  // --min-quality drops what compares greater
  EXPECT_LT(FixQuality::kSbas, FixQuality::kSingle);
}

TEST(GnssFormats, HdopSigmaPolicyGrowsFromFixToSingleWithUpTwiceHorizontal) {
  for (int i = 0; i < kNumFixQualities; ++i) {
    EXPECT_EQ(kQualityPolicy[i].vertical_m, 2.0 * kQualityPolicy[i].horizontal_m) << i;
  }
  EXPECT_EQ(kQualityPolicy[static_cast<int>(FixQuality::kFix)].horizontal_m, 0.01);
  EXPECT_EQ(kQualityPolicy[static_cast<int>(FixQuality::kSingle)].horizontal_m, 2.0);
  for (const FixQuality worse : {FixQuality::kDgps, FixQuality::kSbas, FixQuality::kSingle}) {
    EXPECT_GT(kQualityPolicy[static_cast<int>(worse)].horizontal_m,
              kQualityPolicy[static_cast<int>(worse) - 1].horizontal_m);
  }
}

TEST(GnssFormats, GgaQualityDigitsMapToClassesOrToDroppedEntries) {
  const std::pair<int, FixQuality> kept[] = {{1, FixQuality::kSingle}, {2, FixQuality::kDgps},
                                             {3, FixQuality::kSingle}, {4, FixQuality::kFix},
                                             {5, FixQuality::kFloat},  {9, FixQuality::kSbas}};
  for (const auto& [digit, want] : kept) {
    FixQuality q;
    const char* dropped = nullptr;
    ASSERT_TRUE(GgaQuality(digit, &q, &dropped)) << digit;
    EXPECT_EQ(q, want) << digit;
  }
  for (const int digit : {0, 6, 7, 8}) {
    FixQuality q;
    const char* dropped = nullptr;
    EXPECT_FALSE(GgaQuality(digit, &q, &dropped)) << digit;
    EXPECT_NE(std::string(dropped).find("GGA quality " + std::to_string(digit)), std::string::npos);
  }
}

}  // namespace
}  // namespace gins
