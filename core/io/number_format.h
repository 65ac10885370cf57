// Fast decimal formatting of doubles for the IMU-rate output files, and fast parsing of them back.
// std::to_chars with a precision is correctly rounded but slow (it took ~40 % of an ESKF run); these scale
// to an integer and print its digits.
// They round the scaled value, so a value within one binary rounding of a decimal tie may come out one unit
// in the last place from to_chars's choice; the printed number is always within 0.5 units of the last place
// plus that rounding. Values they cannot do exactly enough (huge, non-finite) go to std::to_chars.
#pragma once

namespace gins {

// Writes v with `precision` (0-9) digits after the point, like printf("%.*f"); returns one past the end,
// or `first` if [first, last) is too short. Never writes "-0.000": a value that rounds to zero is unsigned.
char* FormatFixed(char* first, char* last, double v, int precision);

// Writes v like printf("%.*e") with `precision` (0-9) digits after the point; exponent at least two digits.
char* FormatScientific(char* first, char* last, double v, int precision);

// strtod on the text [first, last) — the same value and the same *end — several times faster on plain
// decimal numbers: std::from_chars (also correctly rounded) takes those, strtod whatever it does not take
// alike (leading whitespace or '+', hex, overflow, underflow, inf and nan). Reading the output files back
// was mostly strtod.
double ParseDouble(const char* first, const char* last, const char** end);

}  // namespace gins
