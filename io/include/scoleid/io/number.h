#pragma once
// A decimal number as people write one in a file: [+|-]digits[.digits][(e|E)[+|-]digits] (or
// .digits). Nothing else is a number here: no hexadecimal (0x10, 0x1p-10, which strtod reads as
// 16 and 0.0009765625), no inf or nan, no leading or trailing blanks. Every reader of scenario
// and data files goes through it, so "0x10" is refused everywhere rather than read somewhere.
#include <string_view>

namespace scoleid::io {

// True and v set when `text` is a decimal number. A value beyond double's range reads as +-inf
// (1e400; callers refuse it as not finite) or 0 (1e-400).
bool parse_decimal(std::string_view text, double& v);
// parse_decimal, and also nan, inf and infinity (any case, signed): numbers a data file may hold,
// which its reader then refuses as not finite, naming them.
bool parse_number(std::string_view text, double& v);

}  // namespace scoleid::io
