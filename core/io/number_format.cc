#include "core/io/number_format.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>

namespace gins {
namespace {

constexpr int kMaxPrecision = 9;
// Exact powers of ten (10^22 is the largest one a double holds exactly).
constexpr double kPow10[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
                             1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
constexpr int kMaxPow10 = 22;
constexpr double kMaxInteger = 1.0e18;  // the integer part fits a uint64_t

// x ≥ 0 (below 2^62) rounded to the nearest integer, ties to even as to_chars does; inline, unlike rint.
uint64_t RoundHalfEven(double x) {
  uint64_t r = static_cast<uint64_t>(x + 0.5);
  if (static_cast<double>(r) - x == 0.5 && (r & 1) != 0) --r;
  return r;
}

char* Fallback(char* first, char* last, double v, std::chars_format format, int precision) {
  const auto r = std::to_chars(first, last, v, format, precision);
  return r.ec == std::errc() ? r.ptr : first;
}

// "00" "01" ... "99": two digits per division halves the dependent chain of divisions.
constexpr char kDigitPairs[] =
    "00010203040506070809101112131415161718192021222324252627282930313233343536373839404142434445464748495051525354"
    "555657585960616263646566676869707172737475767778798081828384858687888990919293949596979899";

// 10^0 ... 10^19, every power of ten a uint64_t holds.
constexpr uint64_t kPow10U[20] = {1ULL,
                                  10ULL,
                                  100ULL,
                                  1000ULL,
                                  10000ULL,
                                  100000ULL,
                                  1000000ULL,
                                  10000000ULL,
                                  100000000ULL,
                                  1000000000ULL,
                                  10000000000ULL,
                                  100000000000ULL,
                                  1000000000000ULL,
                                  10000000000000ULL,
                                  100000000000000ULL,
                                  1000000000000000ULL,
                                  10000000000000000ULL,
                                  100000000000000000ULL,
                                  1000000000000000000ULL,
                                  10000000000000000000ULL};

// Decimal digits of n (0 for 0): from its bit length (1233/4096 ≈ log10 2), then one comparison.
int DigitCount(uint64_t n) {
  const int t = ((64 - __builtin_clzll(n | 1)) * 1233) >> 12;
  return t + 1 - (n < kPow10U[t] ? 1 : 0);
}

// Exactly k digits of n (n < 10^k, zero-padded) from `first`, right to left: the leading zeros come out of
// n's own pairs. The hottest code of an IMU-rate output: four digits per division in 32 bits (a 64-bit one
// only above 2^32, e.g. a time stamp's integer part), two per table look-up.
inline char* WriteExactDigits(char* first, uint64_t n, int k) {
  char* p = first + k;
  while (n > 0xffffffffULL && p - first >= 2) {
    const uint64_t pair = n % 100;
    n /= 100;
    p -= 2;
    std::memcpy(p, kDigitPairs + 2 * pair, 2);
  }
  uint32_t m = static_cast<uint32_t>(n);
  while (p - first >= 4) {
    const uint32_t four = m % 10000;
    m /= 10000;
    p -= 4;
    std::memcpy(p, kDigitPairs + 2 * (four / 100), 2);
    std::memcpy(p + 2, kDigitPairs + 2 * (four % 100), 2);
  }
  if (p - first >= 2) {
    const uint32_t pair = m % 100;
    m /= 100;
    p -= 2;
    std::memcpy(p, kDigitPairs + 2 * pair, 2);
  }
  if (p > first) *--p = static_cast<char>('0' + m % 10);
  return first + k;
}

// Digits of n, at least `min_digits` of them (zero-padded), into [first, last).
inline char* WriteDigits(char* first, char* last, uint64_t n, int min_digits) {
  const int digits = DigitCount(n);
  const int k = digits > min_digits ? digits : (min_digits > 1 ? min_digits : 1);
  if (last - first < k) return nullptr;
  return WriteExactDigits(first, n, k);
}

// "-"? ip "." fp (fp zero-padded to `precision` digits; no point when precision is 0). nullptr if too short.
char* WriteDecimal(char* p, char* last, bool negative, uint64_t ip, uint64_t fp, int precision) {
  if (negative) {
    if (p == last) return nullptr;
    *p++ = '-';
  }
  p = WriteDigits(p, last, ip, 1);
  if (p == nullptr || precision == 0) return p;
  if (last - p < precision + 1) return nullptr;
  *p++ = '.';
  return WriteExactDigits(p, fp, precision);  // fp < 10^precision
}

}  // namespace

char* FormatFixed(char* first, char* last, double v, int precision) {
  if (precision < 0 || precision > kMaxPrecision || !std::isfinite(v) || !(std::abs(v) < kMaxInteger)) {
    return Fallback(first, last, v, std::chars_format::fixed, precision);
  }
  // Integer and fraction apart (both exact), so only the fraction is scaled: a timestamp's 16 digits
  // would lose the last ones in one product. Ties round to even, as to_chars does.
  const double a = std::abs(v);
  const double whole = std::floor(a);
  const uint64_t unit = static_cast<uint64_t>(kPow10[precision]);
  uint64_t ip = static_cast<uint64_t>(whole);
  uint64_t fp = RoundHalfEven((a - whole) * kPow10[precision]);
  if (fp >= unit) {  // the fraction rounded up to one
    fp -= unit;
    ++ip;
  }
  char* p = WriteDecimal(first, last, v < 0.0 && (ip != 0 || fp != 0), ip, fp, precision);
  return p == nullptr ? first : p;
}

char* FormatScientific(char* first, char* last, double v, int precision) {
  if (precision < 0 || precision > kMaxPrecision || !std::isfinite(v) || v == 0.0) {
    return Fallback(first, last, v, std::chars_format::scientific, precision);
  }
  const double a = std::abs(v);
  // The decimal exponent from the binary one, without log10 (a third of the writer's time at IMU rate):
  // a ∈ [2^k, 2^(k+1)) gives floor(k·log10 2) ≤ floor(log10 a), at most one below; the loop below steps it
  // up. Never above: where both e and e + 1 give digits in range (a just below a power of ten), e is right.
  uint64_t bits = 0;
  std::memcpy(&bits, &a, sizeof(bits));
  const int biased = static_cast<int>(bits >> 52) & 0x7ff;  // a = 1.f·2^(biased − 1023); 0: subnormal
  if (biased == 0) return Fallback(first, last, v, std::chars_format::scientific, precision);
  // floor(k·log10 2) in integers: 78913/2^18 ≈ log10 2, exact for |k| ≤ 2620 (a double's k is within ±1023);
  // the arithmetic shift floors negative k. std::floor is a library call on baseline x86-64.
  int e = ((biased - 1023) * 78913) >> 18;
  // Mantissa digits: a / 10^e scaled by 10^precision, computed as one product or quotient of exact powers.
  auto digits = [&](int exp10) -> long long {
    const int shift = precision - exp10;  // a · 10^shift
    if (shift >= 0 && shift <= kMaxPow10) return static_cast<long long>(RoundHalfEven(a * kPow10[shift]));
    if (shift < 0 && shift >= -kMaxPow10) return static_cast<long long>(RoundHalfEven(a / kPow10[-shift]));
    return -1;
  };
  long long n = digits(e);
  const long long lo = static_cast<long long>(kPow10[precision]);
  // Up from the estimate, and once more when the mantissa rounds up to ten (9.99995 -> 10.000).
  for (int step = 0; step < 2 && n >= 10 * lo; ++step) n = digits(++e);
  if (n < lo || n >= 10 * lo) return Fallback(first, last, v, std::chars_format::scientific, precision);
  const uint64_t un = static_cast<uint64_t>(n), ulo = static_cast<uint64_t>(lo);
  char* p = WriteDecimal(first, last, v < 0.0, un / ulo, un % ulo, precision);
  if (p == nullptr) return first;
  if (last - p < 4) return first;
  *p++ = 'e';
  *p++ = e < 0 ? '-' : '+';
  p = WriteDigits(p, last, static_cast<uint64_t>(std::abs(e)), 2);
  return p == nullptr ? first : p;
}

double ParseDouble(const char* first, const char* last, const char** end) {
  double v = 0.0;
  const std::from_chars_result r = std::from_chars(first, last, v);
  // from_chars stops at the 'x' of "0x1p3", where strtod reads a hex number.
  if (r.ec == std::errc() && std::isfinite(v) && (r.ptr == last || (*r.ptr != 'x' && *r.ptr != 'X'))) {
    *end = r.ptr;
    return v;
  }
  const std::string text(first, last);  // rare: strtod needs the end marked
  char* stop = nullptr;
  v = std::strtod(text.c_str(), &stop);
  *end = first + (stop - text.c_str());
  return v;
}

}  // namespace gins
