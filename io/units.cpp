#include "scoleid/io/units.h"

#include "scoleid/io/types.h"

#include <udunits2.h>

#include <cctype>
#include <cmath>
#include <memory>
#include <mutex>
#include <stdexcept>

namespace scoleid::io::units {
namespace {

// UDUNITS-2's unit database, read once (its XML files ship with libudunits2).
ut_system* unit_system() {
  static ut_system* system = [] {
    ut_set_error_message_handler(ut_ignore);
    return ut_read_xml(nullptr);
  }();
  if (!system) throw std::invalid_argument("the UDUNITS-2 unit database could not be read (libudunits2-data)");
  return system;
}

struct UnitFree {
  void operator()(ut_unit* u) const { ut_free(u); }
};
using Unit = std::unique_ptr<ut_unit, UnitFree>;

// The SI unit that stands for a quantity's dimension.
const char* reference(Quantity q) {
  switch (q) {
    case Quantity::Length: return "m";
    case Quantity::Angle: return "rad";
    case Quantity::Velocity: return "m/s";
    case Quantity::Acceleration: return "m/s^2";
    case Quantity::Strain: return "1";
    case Quantity::Force: return "N";
    case Quantity::Moment: return "N.m";
    case Quantity::Time: return "s";
  }
  return "1";
}

bool has_force(Quantity q) { return q == Quantity::Force || q == Quantity::Moment; }

// Replaces each whole-word `word` of text by `by` (words: runs of letters).
std::string replace_word(const std::string& text, const std::string& word, const std::string& by) {
  std::string out;
  std::size_t i = 0;
  while (i < text.size()) {
    const bool start = i == 0 || !std::isalpha(static_cast<unsigned char>(text[i - 1]));
    const std::size_t end = i + word.size();
    if (start && text.compare(i, word.size(), word) == 0 &&
        (end == text.size() || !std::isalpha(static_cast<unsigned char>(text[end])))) {
      out += by;
      i = end;
    } else {
      out += text[i++];
    }
  }
  return out;
}

// Whole labels as DAQ software writes them (LabVIEW's Y_Unit_Label "Newtons", "Pounds", "Inches"),
// read case-insensitively for their quantity: the alias table of units.h.
struct DaqAlias {
  const char* label;
  std::optional<Quantity> quantity;  // nullopt: any
  const char* unit;
};
constexpr DaqAlias kDaqAliases[] = {
    {"newtons", std::nullopt, "N"},          {"newton", std::nullopt, "N"},
    {"pounds", Quantity::Force, "lbf"},      {"pound", Quantity::Force, "lbf"},   {"lbs", Quantity::Force, "lbf"},
    {"lbf", std::nullopt, "lbf"},            {"kilonewtons", std::nullopt, "kN"},
    {"meters", std::nullopt, "m"},           {"metres", std::nullopt, "m"},       {"millimeters", std::nullopt, "mm"},
    {"millimetres", std::nullopt, "mm"},     {"inches", std::nullopt, "in"},      {"inch", std::nullopt, "in"},
    {"feet", std::nullopt, "ft"},            {"seconds", std::nullopt, "s"},      {"sec", std::nullopt, "s"},
    {"gs", Quantity::Acceleration, "standard_free_fall"}, {"g's", Quantity::Acceleration, "standard_free_fall"},
    {"degrees", std::nullopt, "degree"},     {"radians", std::nullopt, "rad"},
};

// The unit text as UDUNITS-2 should read it for quantity q (the header's aliases).
std::string canonical(std::string u, Quantity q) {
  const auto b = u.find_first_not_of(" \t"), e = u.find_last_not_of(" \t");
  u = b == std::string::npos ? std::string() : u.substr(b, e - b + 1);
  {
    std::string low;
    for (char c : u) low += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    for (const auto& a : kDaqAliases)
      if (low == a.label && (!a.quantity || *a.quantity == q)) return a.unit;
  }
  if (q == Quantity::Acceleration && (u == "g" || u == "G" || u == "gn" || u == "g_n")) return "standard_free_fall";
  if (q == Quantity::Strain) {
    for (const char* micro : {"µε", "με", "ue", "uε", "microstrain", "µstrain", "ustrain"})
      if (u == micro) return "1e-6";
    if (u == "ε" || u == "strain" || u == "m/m") return "1";
  }
  if (has_force(q)) u = replace_word(u, "lb", "lbf");
  u = replace_word(replace_word(u, "deg", "degree"), "degrees", "degree");
  return u;
}

// Text that is a number alone ("2", "1e-6") is no unit, though UDUNITS-2 reads it as a
// dimensionless factor that an angle or a strain would accept: a unit names something (a letter or
// a symbol such as ° or µ), but for strain's "1" and "%".
bool names_a_unit(const std::string& text, Quantity q) {
  for (unsigned char c : text)
    if (std::isalpha(c) || c >= 0x80) return true;
  return q == Quantity::Strain && (text == "1" || text == "%");
}

// UDUNITS-2 keeps global state (the parser, its status): one caller at a time.
std::mutex& parser_lock() {
  static std::mutex m;
  return m;
}

Unit parse(const std::string& text) {
  if (text.empty()) return Unit(nullptr);
  const std::lock_guard<std::mutex> lock(parser_lock());
  return Unit(ut_parse(unit_system(), text.c_str(), UT_UTF8));
}

}  // namespace

const char* quantity_name(Quantity q) {
  switch (q) {
    case Quantity::Length: return "length";
    case Quantity::Angle: return "angle";
    case Quantity::Velocity: return "velocity";
    case Quantity::Acceleration: return "acceleration";
    case Quantity::Strain: return "strain";
    case Quantity::Force: return "force";
    case Quantity::Moment: return "moment";
    case Quantity::Time: return "time";
  }
  return "?";
}

std::optional<Quantity> quantity_of_kind(const std::string& kind) {
  if (const auto k = io::parse<io::SensorKind>(kind)) return io::sensor_traits(*k).quantity;
  if (kind == "force") return Quantity::Force;
  if (kind == "moment") return Quantity::Moment;
  return std::nullopt;
}

const char* system_name(System s) {
  switch (s) {
    case System::None: return "";
    case System::SI: return "SI";
    case System::SlugFtS: return "slug-ft-s";
  }
  return "";
}

std::optional<System> parse_system(const std::string& name) {
  if (name == "SI") return System::SI;
  if (name == "slug-ft-s") return System::SlugFtS;
  return std::nullopt;
}

std::string system_unit(System s, Quantity q) {
  if (s != System::SlugFtS) return s == System::SI ? reference(q) : "";
  switch (q) {
    case Quantity::Length: return "ft";
    case Quantity::Velocity: return "ft/s";
    case Quantity::Acceleration: return "ft/s^2";
    case Quantity::Force: return "lbf";
    case Quantity::Moment: return "lbf.ft";
    default: return reference(q);
  }
}

std::optional<std::string> problem_with(const std::string& unit, Quantity q) {
  const std::string text = canonical(unit, q);
  const Unit u = parse(text), ref = parse(reference(q));
  if (!u || !names_a_unit(unit, q)) return "'" + unit + "' is not a unit UDUNITS-2 knows";
  // Convertible in UDUNITS-2 includes reciprocals (Hz and s, s/m and m/s): a unit of q converts
  // into q's reference by a finite positive factor.
  const std::lock_guard<std::mutex> lock(parser_lock());
  bool ok = ut_are_convertible(u.get(), ref.get()) != 0;
  if (ok) {
    cv_converter* cv = ut_get_converter(u.get(), ref.get());
    const double one = cv ? cv_convert_double(cv, 1.0) - cv_convert_double(cv, 0.0) : 0.0;
    if (cv) cv_free(cv);
    ok = std::isfinite(one) && one > 0;
  }
  if (!ok) return "'" + unit + "' is not a unit of " + quantity_name(q);
  return std::nullopt;
}

Conversion conversion(const std::string& from, const std::string& to, Quantity q) {
  for (const auto* u : {&from, &to})
    if (const auto why = problem_with(*u, q)) throw std::invalid_argument(*why);
  const Unit a = parse(canonical(from, q)), b = parse(canonical(to, q));
  const std::lock_guard<std::mutex> lock(parser_lock());
  cv_converter* cv = ut_get_converter(a.get(), b.get());
  if (!cv) throw std::invalid_argument("'" + from + "' cannot be converted into '" + to + "'");
  Conversion c{from, to, 1.0, 0.0};
  c.offset = cv_convert_double(cv, 0.0);
  c.scale = cv_convert_double(cv, 1.0) - c.offset;
  cv_free(cv);
  // UDUNITS composes factors in floating point: a conversion that is the identity up to rounding
  // (ft/s^2 into ft/s2, lbf.ft into lb ft) is the identity.
  if (!std::isfinite(c.scale) || !std::isfinite(c.offset) || !(c.scale > 0))
    throw std::invalid_argument("'" + from + "' cannot be converted into '" + to + "'");
  if (std::abs(c.scale - 1.0) < 1e-14) c.scale = 1.0;
  if (std::abs(c.offset) < 1e-300) c.offset = 0.0;
  return c;
}

std::string bracketed_unit(const std::string& header) {
  const auto e = header.find_last_not_of(" \t");
  if (e == std::string::npos) return "";
  const char close = header[e];
  if (close != ']' && close != ')') return "";
  const auto open = header.rfind(close == ']' ? '[' : '(', e);
  if (open == std::string::npos) return "";
  std::string inside = header.substr(open + 1, e - open - 1);
  const auto b = inside.find_first_not_of(" \t"), ie = inside.find_last_not_of(" \t");
  inside = b == std::string::npos ? std::string() : inside.substr(b, ie - b + 1);
  if (close == ')') {
    bool unit = false;
    for (Quantity q : {Quantity::Length, Quantity::Angle, Quantity::Velocity, Quantity::Acceleration, Quantity::Strain,
                       Quantity::Force, Quantity::Moment, Quantity::Time})
      unit = unit || (names_a_unit(inside, q) && parse(canonical(inside, q)));
    if (!unit) return "";
  }
  return inside;
}

}  // namespace scoleid::io::units
