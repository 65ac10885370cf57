#include "core/io/number_format.h"

#include <gtest/gtest.h>

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

namespace gins {
namespace GINS_TEST_FILE {

std::string Ours(double v, int precision, bool scientific) {
  char buf[64];
  char* end = scientific ? FormatScientific(buf, buf + sizeof(buf), v, precision)
                         : FormatFixed(buf, buf + sizeof(buf), v, precision);
  return std::string(buf, end);
}

std::string Reference(double v, int precision, bool scientific) {
  char buf[512];
  const auto r = std::to_chars(buf, buf + sizeof(buf), v,
                               scientific ? std::chars_format::scientific : std::chars_format::fixed, precision);
  std::string s(buf, r.ptr);
  // We never write a negative zero ("-0.000"); to_chars does for tiny negative values.
  if (!scientific && s[0] == '-' && s.find_first_not_of("-0.") == std::string::npos) s.erase(0, 1);
  return s;
}

TEST(NumberFormat, MatchesToCharsOnTypicalValues) {
  const double values[] = {0.0, 1.0, -1.0, 0.5, 9.999995, 1700000002.000001, 123.456789, -0.00072, 1e-5,
                           -3.2e-7, 99999.999999, 1e-300, 6.02e23, 2.5e-15};
  for (double v : values) {
    for (int p : {0, 4, 5, 6, 9}) {
      EXPECT_EQ(Ours(v, p, false), Reference(v, p, false)) << v << " fixed " << p;
      EXPECT_EQ(Ours(v, p, true), Reference(v, p, true)) << v << " scientific " << p;
    }
  }
}

// The decimal exponent comes from the binary one: next to every power of ten (where the exponent changes, and
// where a mantissa rounds up to 10) the text is to_chars's exactly (decimal ties aside, see below).
TEST(NumberFormat, ScientificMatchesToCharsNextToPowersOfTen) {
  for (int e = -30; e <= 30; ++e) {
    const double p10 = std::pow(10.0, e);
    const double values[] = {p10, std::nextafter(p10, 0.0), std::nextafter(p10, 1e300), p10 * (1.0 - 4e-5),
                             p10 * (1.0 - 6e-5), p10 * (1.0 - 4e-10), p10 * 2.0, p10 * 0.5};
    for (double v : values) {
      for (int p = 0; p <= 9; ++p) {
        EXPECT_EQ(Ours(v, p, true), Reference(v, p, true)) << v << " scientific " << p;
        EXPECT_EQ(Ours(-v, p, true), Reference(-v, p, true)) << -v << " scientific " << p;
      }
    }
  }
}

// Random values over the ranges the output files carry: the text is to_chars's except, rarely, one unit in
// the last place at a decimal tie, and always parses back within half a unit (plus binary rounding).
TEST(NumberFormat, RandomValuesWithinHalfAUnitOfTheLastPlace) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> mantissa(-10.0, 10.0);
  std::uniform_int_distribution<int> exponent(-12, 9);
  int differ = 0, n = 0;
  for (int i = 0; i < 200000; ++i) {
    const double v = mantissa(rng) * std::pow(10.0, exponent(rng));
    for (bool sci : {false, true}) {
      const int p = sci ? 4 : 6;
      const std::string ours = Ours(v, p, sci);
      ++n;
      if (ours != Reference(v, p, sci)) ++differ;
      const double back = std::stod(ours);
      const double unit = sci ? std::pow(10.0, std::floor(std::log10(std::abs(v))) - p) : std::pow(10.0, -p);
      ASSERT_LE(std::abs(back - v), 0.5 * unit * (1.0 + 1e-9) + 1e-15 * std::abs(v)) << ours << " for " << v;
    }
  }
  EXPECT_LT(differ, n / 10000) << differ << " of " << n << " differ from to_chars";
}

TEST(NumberFormat, NonFiniteAndTooShortBuffers) {
  EXPECT_EQ(Ours(std::nan(""), 3, false), Reference(std::nan(""), 3, false));
  EXPECT_EQ(Ours(-INFINITY, 3, true), Reference(-INFINITY, 3, true));
  EXPECT_EQ(Ours(1e20, 3, false), Reference(1e20, 3, false));  // beyond 2^53 scaled: to_chars
  char buf[4];
  EXPECT_EQ(FormatFixed(buf, buf + sizeof(buf), 123.456, 2), buf);  // does not fit: nothing written
  EXPECT_EQ(FormatScientific(buf, buf + sizeof(buf), 123.456, 2), buf);
}

// ParseDouble is strtod on the range, value and end alike, for what from_chars takes and what it leaves to
// strtod.
TEST(ParseDouble, IsStrtodOnTheRange) {
  std::vector<std::string> texts = {"0",        "1.5",      "-2.25e-3", "1700000002.000001", "12,3",   "  7",
                                    "+4",       "0x1p3",    "-0X1.8p1", "1e",        "1e+",    "1.e5",
                                    ".5",       "-.5e1",    "1e400",    "-1e400",    "1e-400", "4.9e-324",
                                    "inf",      "-INF",     "nan",      "nan(123)",  "abc",    "",
                                    "-",        "1.5 2.5",  "3\r\n",    "1..2",      "0.1e-5x", "\t8"};
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> mantissa(-10.0, 10.0);
  std::uniform_int_distribution<int> exponent(-300, 300);
  for (int i = 0; i < 2000; ++i) {
    char buf[64];
    std::snprintf(buf, sizeof(buf), i % 2 ? "%.17g" : "%.6f", mantissa(rng) * std::pow(10.0, exponent(rng) / 10));
    texts.push_back(buf);
  }
  for (const std::string& text : texts) {
    char* want_end = nullptr;
    const double want = std::strtod(text.c_str(), &want_end);
    const char* end = nullptr;
    const double got = ParseDouble(text.data(), text.data() + text.size(), &end);
    EXPECT_EQ(end - text.data(), want_end - text.c_str()) << "'" << text << "'";
    if (std::isnan(want)) {
      EXPECT_TRUE(std::isnan(got)) << "'" << text << "'";
    } else {
      EXPECT_EQ(got, want) << "'" << text << "'";
    }
  }
  // Only the range is read: a number cut short by `last`.
  const char* text = "123.456";
  const char* end = nullptr;
  EXPECT_EQ(ParseDouble(text, text + 3, &end), 123.0);
  EXPECT_EQ(end, text + 3);
}

}  // namespace
}  // namespace gins
