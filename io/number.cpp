#include "scoleid/io/number.h"

#include <cctype>
#include <charconv>
#include <string>
#include <cmath>
#include <system_error>

namespace scoleid::io {

bool parse_decimal(std::string_view text, double& v) {
  if (text.size() > 1 && text.front() == '+' && text[1] != '-' && text[1] != '+') text.remove_prefix(1);
  std::size_t i = 0;
  if (i < text.size() && text[i] == '-') ++i;
  // The grammar first (from_chars would also take "inf", "nan" and, with hex, "1p3").
  std::size_t digits = 0;
  while (i < text.size() && text[i] >= '0' && text[i] <= '9') ++i, ++digits;
  if (i < text.size() && text[i] == '.') {
    ++i;
    while (i < text.size() && text[i] >= '0' && text[i] <= '9') ++i, ++digits;
  }
  if (digits == 0) return false;
  if (i < text.size() && (text[i] == 'e' || text[i] == 'E')) {
    ++i;
    if (i < text.size() && (text[i] == '+' || text[i] == '-')) ++i;
    std::size_t exp = 0;
    while (i < text.size() && text[i] >= '0' && text[i] <= '9') ++i, ++exp;
    if (exp == 0) return false;
  }
  if (i != text.size()) return false;
  double x = 0.0;
  const auto r = std::from_chars(text.data(), text.data() + text.size(), x, std::chars_format::general);
  if (r.ec == std::errc::result_out_of_range) {
    // Beyond double's range: below it reads as 0 (zero to every use here), above it as inf, which
    // the caller refuses as not finite (naming the value as written).
    const auto e = text.find_first_of("eE");
    const bool small = e != std::string_view::npos && text.substr(e + 1).find('-') == 0;
    const bool negative = text.front() == '-';
    v = small ? (negative ? -0.0 : 0.0) : (negative ? -HUGE_VAL : HUGE_VAL);
    return true;
  }
  if (r.ec != std::errc() || r.ptr != text.data() + text.size()) return false;
  v = x;
  return true;
}

bool parse_number(std::string_view text, double& v) {
  if (parse_decimal(text, v)) return true;
  std::string low;
  for (char c : text) low += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  const bool negative = !low.empty() && low[0] == '-';
  if (!low.empty() && (low[0] == '-' || low[0] == '+')) low.erase(0, 1);
  if (low == "nan") v = std::nan("");
  else if (low == "inf" || low == "infinity") v = negative ? -HUGE_VAL : HUGE_VAL;
  else return false;
  return true;
}

}  // namespace scoleid::io
