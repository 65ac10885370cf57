// ParseNumber: a log token read as strtod reads it, bit for bit, in the forms log writers make.
#include "core/io/text_input.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>

namespace gins {
namespace GINS_TEST_FILE {

// The reference: strtod over the whole token (ParseNumber also takes a leading '+').
void ExpectStrtod(const std::string& token) {
  double v = 0.0;
  ASSERT_EQ(ParseNumber(token, &v), NumberStatus::kOk) << token;
  const double expected = std::strtod(token.c_str(), nullptr);
  EXPECT_EQ(std::memcmp(&v, &expected, sizeof(v)), 0) << token << ": " << v << " vs " << expected;
}

TEST(ParseNumber, IsStrtodOnTheFormsLogsUse) {
  for (const char* token :
       {"0", "-0", "-0.0", "+1.5", "1700000000.000000", "1700000002.010000", "-2.361976476e-03", "9.884716606e+00",
        "31.5081804718", "120.4019898559", "0.1", "0.3", "123456789012345678", "9007199254740991",
        "9007199254740993", "1e22", "1e23", "1e-22", "1e-23", "4.9e-324", "1.7976931348623157e308", "1E5", "1e+0005",
        "0.000000000000000000000000001", "12345678901234567890123", "1700000000.123456789"}) {
    ExpectStrtod(token);
  }
}

// Random tokens in the printf forms a log writer makes (%.*e, %.*f, %.*g): every one is strtod's value.
TEST(ParseNumber, IsStrtodOnRandomTokens) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> mantissa(-10.0, 10.0);
  std::uniform_int_distribution<int> exponent(-30, 30), precision(0, 17), form(0, 2);
  char buf[64];
  for (int i = 0; i < 200000; ++i) {
    const double x = mantissa(rng) * std::pow(10.0, exponent(rng));
    const int p = precision(rng);
    const int f = form(rng);
    std::snprintf(buf, sizeof(buf), f == 0 ? "%.*e" : f == 1 ? "%.*f" : "%.*g", p, x);
    ExpectStrtod(buf);
  }
}

TEST(ParseNumber, RejectsWhatItRejectedBefore) {
  double v = 0.0;
  for (const char* token : {"", "-", "+", "+-1", "-+1", "1.", ".5e", "1e", "1e+", "1..2", "1.2.3", "0x10", "1,5",
                            "12a", " 1", "1 "}) {
    const NumberStatus status = ParseNumber(token, &v);
    if (status == NumberStatus::kOk) {
      // Forms from_chars takes ("1.", ".5"...) stay taken, with strtod's value.
      ExpectStrtod(token);
    } else {
      EXPECT_EQ(status, NumberStatus::kBad) << token;
    }
  }
  EXPECT_EQ(ParseNumber("1e400", &v), NumberStatus::kNonFinite);
  EXPECT_EQ(ParseNumber("nan", &v), NumberStatus::kNonFinite);
}

}  // namespace
}  // namespace gins
