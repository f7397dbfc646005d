#include <cctype>
#include <cmath>
#include <cstdarg>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "scoleid/io/data_files.h"
#include "scoleid/io/error.h"
#include "scoleid/io/interrupt.h"
#include "scoleid/io/uff.h"
#include "scoleid/io/units.h"
#include "scoleid/io/validation.h"

namespace scoleid::io::uff {

namespace {

std::string format(const char* fmt, ...) __attribute__((format(printf, 1, 2)));
std::string format(const char* fmt, ...) {
  char b[256];
  va_list ap;
  va_start(ap, fmt);
  std::vsnprintf(b, sizeof b, fmt, ap);
  va_end(ap);
  return b;
}

// The most precise E-format of v that fits a 13-character field, and the value it reads back as.
std::pair<std::string, double> field13(double v) {
  for (int digits = 8; digits >= 1; --digits) {
    const std::string s = format("%13.*E", digits - 1, v);
    if (s.size() <= 13) return {s, std::strtod(s.c_str(), nullptr)};
  }
  return {format("%13.5E", v), v};  // not reached for a finite double
}

// The even abscissa (minimum, increment) as the header writes them, when x_k = min + k·increment
// read back from those fields gives every time exactly (what read_file computes); nullopt otherwise.
bool even_abscissa(const std::vector<double>& t, std::string& min_text, std::string& inc_text) {
  const std::size_t n = t.size();
  const double candidates[] = {(t.back() - t.front()) / static_cast<double>(n - 1), t[1] - t[0]};
  const auto [m, m_read] = field13(t.front());
  for (const double dt : candidates) {
    if (!std::isfinite(dt) || !(dt > 0)) continue;
    const auto [d, d_read] = field13(dt);
    bool exact = m_read == t.front();
    for (std::size_t k = 0; k < n && exact; ++k) exact = m_read + static_cast<double>(k) * d_read == t[k];
    if (exact) {
      min_text = m;
      inc_text = d;
      return true;
    }
  }
  return false;
}

// The specific data type of a column's unit (0 unknown): 8 displacement, 11 velocity,
// 12 acceleration, 13 excitation force, 3 strain.
int spec_type_of(const std::string& unit) {
  using units::Quantity;
  if (unit.empty()) return 0;
  const std::pair<Quantity, int> rows[] = {{Quantity::Acceleration, 12}, {Quantity::Velocity, 11}, {Quantity::Length, 8},
                                           {Quantity::Force, 13},        {Quantity::Strain, 3}};
  for (const auto& [q, code] : rows)
    if (!units::problem_with(unit, q)) return code;
  return 0;
}

void put_double(std::string& out, double v, bool swap) {
  unsigned char b[8];
  std::memcpy(b, &v, 8);
  if (swap)
    for (int i = 0; i < 4; ++i) std::swap(b[i], b[7 - i]);
  out.append(reinterpret_cast<const char*>(b), 8);
}

}  // namespace

void write_file(const DataTable& tab, const std::string& path) {
  const std::string where = "UFF file '" + path + "'";
  try {
    check_table(tab);
  } catch (const InputError& e) {
    throw InputError(one_line(where + ": cannot be written: " + e.what()));
  }
  auto refuse = [&](const std::string& what) { throw InputError(one_line(where + ": cannot be written: " + what)); };
  auto printable = [](const std::string& s) {
    for (unsigned char c : s)
      if (c < 0x20 || c == 0x7f) return false;
    return first_invalid_utf8(s) == std::string::npos;
  };
  auto unpadded = [](const std::string& s) { return s.empty() || (s.front() != ' ' && s.back() != ' '); };
  // The reader takes NONE in any case for "no name" / "no unit".
  auto none = [](const std::string& s) {
    std::string u = s;
    for (char& c : u) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    return u == "NONE";
  };
  for (std::size_t j = 0; j < tab.names.size(); ++j) {
    const std::string& name = tab.names[j];
    const std::string unit = tab.unit(static_cast<int>(j));
    if (!printable(name) || name.size() > 80 || !unpadded(name) || name.empty() || none(name))
      refuse("column name '" + shorten(name) + "' does not fit ID line 1 (printable UTF-8 of at most 80 bytes, no blank at either end, not NONE in any case)");
    if (!printable(unit) || unit.size() > 20 || !unpadded(unit) || none(unit))
      refuse("the unit '" + shorten(unit) + "' of column '" + shorten(name) +
             "' does not fit the axis units label (printable UTF-8 of at most 20 bytes, no blank at either end, not NONE in any case)");
    // channel_names makes a repeated name unique with '#k': a name of that form could collide.
    if (name.find('#') != std::string::npos) {
      const auto p = name.rfind('#');
      const std::string tail = name.substr(p + 1);
      if (!tail.empty() && tail.find_first_not_of("0123456789") == std::string::npos)
        refuse("column name '" + shorten(name) + "' ends in '#<number>', which the reader gives repeated names");
    }
  }
  const std::size_t n = tab.t.size();
  std::string min_text, inc_text;
  const bool even = even_abscissa(tab.t, min_text, inc_text);
  if (!even) min_text = inc_text = format("%13.5E", 0.0);
  const std::size_t per_point = even ? 1 : 2;
  const std::uint64_t block = static_cast<std::uint64_t>(n) * per_point * 8;
  if (block > 2147483647ULL) refuse("a function of " + std::to_string(block) + " bytes is past the n_bytes field's 2^31 - 1");
  const bool swap = [] {
    const std::uint16_t one = 1;
    unsigned char first = 0;
    std::memcpy(&first, &one, 1);
    return first != 1;  // written little endian
  }();
  std::string out;
  out.reserve(tab.names.size() * (static_cast<std::size_t>(block) + 1024));
  out += format("%6i\n%6i\n", -1, 151);
  out += "scoleid record\nmeasured functions\nscole-data\n";
  out += format("%10s%10s%10i%10i%10i\n", "", "", 0, 0, 0);
  out += format("%10s%10s\n", "", "");
  out += "scole-data\n";
  out += format("%10s%10s\n", "", "");
  out += format("%6i\n", -1);
  for (std::size_t j = 0; j < tab.names.size(); ++j) {
    check_interrupt();
    const std::string unit = tab.unit(static_cast<int>(j));
    out += format("%6i\n", -1);
    out += format("%6i%c%6i%6i%12i%12llu%6i%6i%12i%12i\n", 58, 'b', 1, 2, 11, static_cast<unsigned long long>(block), 0, 0, 0, 0);
    out += tab.names[j] + "\n" + "NONE\nNONE\nNONE\nNONE\n";
    // Line 6: a time response of response node j+1, scalar, no reference.
    out += format("%5i%10i%5i%10i %-10s%10i%4i %-10s%10i%4i\n", 1, static_cast<int>(j + 1), 0, 0, "NONE",
                  static_cast<int>(j + 1), 0, "NONE", 0, 0);
    out += format("%10i%10llu%10i", 4, static_cast<unsigned long long>(n), even ? 1 : 0) + min_text + inc_text + format("%13.5E\n", 0.0);
    out += format("%10i%5i%5i%5i %-20s %-20s\n", 17, 0, 0, 0, "Time", "s");
    out += format("%10i%5i%5i%5i %-20s %-20s\n", spec_type_of(unit), 0, 0, 0, "NONE", unit.empty() ? "NONE" : unit.c_str());
    out += format("%10i%5i%5i%5i %-20s %-20s\n", 0, 0, 0, 0, "NONE", "NONE");
    out += format("%10i%5i%5i%5i %-20s %-20s\n", 0, 0, 0, 0, "NONE", "NONE");
    const auto& col = tab.columns[j];
    for (std::size_t k = 0; k < n; ++k) {
      if (!even) put_double(out, tab.t[k], swap);
      put_double(out, col[k], swap);
    }
    out += format("\n%6i\n", -1);
  }
  write_text_atomic(path, out);
}

}  // namespace scoleid::io::uff
