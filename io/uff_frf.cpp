// Frequency response functions in a Universal File: reading them into FRF data and writing FRF
// data as ASCII datasets 58. The rules (stations, signs, lines, units, variances) are stated in
// scoleid/io/uff_frf.h.
#include "scoleid/io/uff_frf.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <complex>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <stdexcept>

#include "scoleid/io/data_files.h"
#include "scoleid/io/error.h"
#include "scoleid/io/limits.h"
#include "scoleid/io/validation.h"

namespace scoleid::io {
namespace {

constexpr int kFrf = 4;        // function type: Frequency Response Function
constexpr int kCoherence = 6;  // function type: Coherence
constexpr int kFrequency = 18, kDisplacement = 8, kVelocity = 11, kAcceleration = 12, kForce = 13;  // specific data types
const char* const kStationForm = "must be <node><+|-><X|Y|Z|RX|RY|RZ> (e.g. 12+Y) or <node> (scalar)";

std::string format(const char* fmt, ...) __attribute__((format(printf, 1, 2)));
std::string format(const char* fmt, ...) {
  char b[256];
  va_list ap;
  va_start(ap, fmt);
  std::vsnprintf(b, sizeof b, fmt, ap);
  va_end(ap);
  return b;
}

std::string quoted(const std::string& s) { return "'" + shorten(s) + "'"; }

// ---------------------------------------------------------------------------------------------
// Degrees of freedom.

struct Dof {
  int node = 0;
  int axis = 0;  // 0 scalar, 1..6: X Y Z RX RY RZ (the magnitude of a UFF direction)
  int sign = 1;
  int direction() const { return sign * axis; }
  bool at(int n, int direction) const { return n == node && std::abs(direction) == axis; }
};

std::string dof_name(int node, int direction) { return std::to_string(node) + uff::direction_name(direction); }

// "<node><sign><axis>" or "<node>"; nullopt when malformed.
std::optional<Dof> parse_dof(const std::string& text) {
  Dof d;
  std::size_t i = 0;
  while (i < text.size() && std::isdigit(static_cast<unsigned char>(text[i]))) ++i;
  if (i == 0 || i > 9) return std::nullopt;
  d.node = std::atoi(text.substr(0, i).c_str());
  if (i == text.size()) return d;
  if (text[i] != '+' && text[i] != '-') return std::nullopt;
  d.sign = text[i] == '-' ? -1 : 1;
  const std::string axis = text.substr(i + 1);
  const char* names[] = {"X", "Y", "Z", "RX", "RY", "RZ"};
  for (int a = 0; a < 6; ++a)
    if (axis == names[a]) {
      d.axis = a + 1;
      return d;
    }
  return std::nullopt;
}

Dof option_dof(const std::string& text, const std::string& source, const std::string& field) {
  const auto d = parse_dof(text);
  if (!d) fail_field(source, field, kStationForm, quoted(text));
  return *d;
}

// ---------------------------------------------------------------------------------------------
// Messages about one function of the file.

std::string record_of(const std::string& path, const uff::Function& f) {
  return "UFF file '" + path + "': record " + std::to_string(f.record) + " (dataset 58" + (f.binary ? "b" : "") +
         " at line " + std::to_string(f.line) + ", " + uff::function_type_name(f.function_type) + " at " +
         dof_name(f.response_node, f.response_direction) + " per " + dof_name(f.reference_node, f.reference_direction) +
         ")";
}

[[noreturn]] void fail_record(const std::string& path, const uff::Function& f, const std::string& field,
                              const std::string& requirement, const std::string& got) {
  throw InputError(one_line(record_of(path, f) + ": " + field + " " + requirement + ", got " + got));
}

std::string list(const std::vector<std::string>& items) {
  std::string out;
  for (std::size_t i = 0; i < items.size() && i < 12; ++i) out += (i ? ", " : "") + items[i];
  if (items.size() > 12) out += ", ... (" + std::to_string(items.size()) + " in all)";
  return out;
}

// ---------------------------------------------------------------------------------------------
// Units. Nothing else in the reader turns a function's values into SI (the time responses keep
// their file units and units label), so this is the one place dataset 164 and the axes' exponents
// are applied.

// SDRL's factors (units per SI unit) of the unit systems dataset 164 names by code.
struct SystemFactors {
  int code;
  double length, force;
};
const SystemFactors kSystems[] = {
    {1, 1.0, 1.0},                                  // SI: meter, newton
    {2, 1.0 / 0.3048, 1.0 / 4.4482216152605},       // BG: foot, pound force
    {3, 1.0, 1.0 / 9.80665},                        // MG: meter, kilogram force
    {4, 1.0 / 0.3048, 1.0 / 0.138254954376},        // BA: foot, poundal
    {5, 1000.0, 1000.0},                            // MM: mm, milli-newton
    {6, 100.0, 100.0},                              // CM: cm, centi-newton
    {7, 1.0 / 0.0254, 1.0 / 4.4482216152605},       // IN: inch, pound force
    {8, 1000.0, 1.0 / 9.80665},                     // GM: mm, kilogram force
    {10, 1000.0, 1.0},                              // MN: mm, newton
};

bool same_factor(double a, double b) { return std::abs(a - b) <= 1e-6 * std::abs(b); }

// The factor as SDRL defines it (file units per SI unit): as written, unless the code names a
// system and the factor written is the inverse of that system's.
double sdrl_factor(const uff::Units& u, bool length) {
  const double written = length ? u.length : u.force;
  for (const auto& s : kSystems) {
    if (s.code != u.code) continue;
    const double expected = length ? s.length : s.force;
    if (!same_factor(written, expected) && same_factor(1.0 / written, expected)) return 1.0 / written;
  }
  return written;
}

// H_SI / H_file for an FRF of `f` (uff_frf.h, Units).
double si_factor(const std::string& path, const uff::File& file, const uff::Function& f) {
  if (!file.units) return 1.0;
  const double L = sdrl_factor(*file.units, true), F = sdrl_factor(*file.units, false);
  const int da = f.ordinate.length_exp - f.denominator.length_exp;
  const int db = f.ordinate.force_exp - f.denominator.force_exp;
  const int axis = std::abs(f.response_direction);
  const std::string units = "dataset 164 (record " + std::to_string(file.units->record) + ", code " +
                            std::to_string(file.units->code) + ": length factor " + format_value(L) + ", force factor " +
                            format_value(F) + ")";
  if (L != 1.0 && axis != 0 && da != (axis <= 3 ? 1 : 0))
    fail_record(path, f, "ordinate length units exponent less the denominator's",
                std::string("must be ") + (axis <= 3 ? "1 for a translation" : "0 for a rotation") +
                    " per force to be converted into SI with " + units,
                std::to_string(f.ordinate.length_exp) + " - " + std::to_string(f.denominator.length_exp));
  if (F != 1.0 && db != -1)
    fail_record(path, f, "ordinate force units exponent less the denominator's",
                "must be -1 for a response per force to be converted into SI with " + units,
                std::to_string(f.ordinate.force_exp) + " - " + std::to_string(f.denominator.force_exp));
  return std::pow(L, -da) * std::pow(F, -db);
}

// ---------------------------------------------------------------------------------------------
// Reading.

int response_order(int spec) { return spec == kDisplacement ? 0 : spec == kVelocity ? 1 : spec == kAcceleration ? 2 : -1; }

bool is_hz(const std::string& unit) {
  if (unit.size() != 2) return unit.empty();
  return std::tolower(static_cast<unsigned char>(unit[0])) == 'h' && std::tolower(static_cast<unsigned char>(unit[1])) == 'z';
}

// The abscissa of f as lines in Hz, a leading 0 Hz line dropped (`dropped` tells).
std::vector<double> lines_of(const std::string& path, const uff::Function& f, bool& dropped) {
  if (f.abscissa.spec_type != kFrequency)
    fail_record(path, f, "abscissa specific data type", "must be 18 (frequency)", std::to_string(f.abscissa.spec_type));
  if (!is_hz(uff::abscissa_unit(f)))
    fail_record(path, f, "abscissa units label", "must be Hz (or NONE)", quoted(uff::abscissa_unit(f)));
  dropped = !f.x.empty() && f.x.front() == 0.0;
  std::vector<double> x(f.x.begin() + (dropped ? 1 : 0), f.x.end());
  if (x.empty()) fail_record(path, f, "num_pts", "must give a line above 0 Hz", std::to_string(f.points));
  for (std::size_t k = 0; k < x.size(); ++k) {
    const std::size_t point = k + (dropped ? 2 : 1);
    if (!std::isfinite(x[k]) || !(x[k] > 0))
      fail_record(path, f, "abscissa value " + std::to_string(point), "must be a frequency > 0 Hz", format_value(x[k]));
    if (k > 0 && !(x[k] > x[k - 1]))
      fail_record(path, f, "abscissa value " + std::to_string(point), "must be above the one before (" + format_value(x[k - 1]) + " Hz)",
                  format_value(x[k]));
  }
  return x;
}

std::string grid_text(const std::vector<double>& x) {
  return std::to_string(x.size()) + " lines " + format_value(x.front()) + " to " + format_value(x.back()) + " Hz";
}

// Same lines as `first` (of function `of`), within 1e-9 of each line.
void check_same_lines(const std::string& path, const uff::Function& f, const std::vector<double>& x,
                      const uff::Function& of, const std::vector<double>& first) {
  std::size_t differ = x.size() == first.size() ? x.size() : 0;
  for (std::size_t k = 0; k < std::min(x.size(), first.size()); ++k)
    if (!(std::abs(x[k] - first[k]) <= 1e-9 * std::max(std::abs(x[k]), std::abs(first[k])))) {
      differ = k;
      break;
    }
  if (differ == x.size() && x.size() == first.size()) return;
  std::string detail = x.size() == first.size()
                           ? ": line " + std::to_string(differ + 1) + " is " + format_value(x[differ]) + " Hz against " +
                                 format_value(first[differ]) + " Hz"
                           : "";
  fail_record(path, f, "lines",
              "must be those of record " + std::to_string(of.record) + " (" + grid_text(first) + detail +
                  "): every station's FRF and coherence share one set of lines",
              grid_text(x));
}

void check_options(const UffFrfOptions& o) {
  if (!(std::isfinite(o.relative_std) && o.relative_std >= 0))
    fail_field(o.source, "frf.relative_std", "must be a relative standard deviation >= 0", format_value(o.relative_std));
  if (o.averages < 0) fail_field(o.source, "frf.averages", "must be >= 0", std::to_string(o.averages));
  if (o.stations.empty()) fail_field(o.source, "frf.stations", "must name at least one sensor", "none");
}

std::vector<const uff::Function*> functions_of_type(const uff::File& file, int type) {
  std::vector<const uff::Function*> out;
  for (const auto& f : file.functions)
    if (f.function_type == type) out.push_back(&f);
  return out;
}

// The reference: the one given, or the one all FRFs share.
Dof reference_of(const std::vector<const uff::Function*>& frfs, const std::string& path, const UffFrfOptions& o) {
  std::vector<std::string> refs;
  for (const auto* f : frfs) {
    const std::string r = dof_name(f->reference_node, std::abs(f->reference_direction));
    if (std::find(refs.begin(), refs.end(), r) == refs.end()) refs.push_back(r);
  }
  if (o.reference.empty()) {
    if (refs.size() > 1)
      fail_field(o.source, "frf.reference",
                 "must name the excitation: the FRFs in UFF file '" + path + "' have several references (" + list(refs) + ")",
                 "''");
    Dof d;
    d.node = frfs.front()->reference_node;
    d.axis = std::abs(frfs.front()->reference_direction);
    d.sign = frfs.front()->reference_direction < 0 ? -1 : 1;
    return d;
  }
  const Dof d = option_dof(o.reference, o.source, "frf.reference");
  for (const auto* f : frfs)
    if (d.at(f->reference_node, f->reference_direction)) return d;
  fail_field(o.source, "frf.reference",
             "must be the reference of a frequency response function (function type 4) in UFF file '" + path +
                 "', whose references are " + list(refs),
             quoted(o.reference));
}

// The one function among `fs` at response `r` and reference `ref`, or null; two are refused.
const uff::Function* one_at(const std::string& path, const std::vector<const uff::Function*>& fs, const Dof& r,
                            const Dof& ref) {
  const uff::Function* found = nullptr;
  for (const auto* f : fs) {
    if (!r.at(f->response_node, f->response_direction) || !ref.at(f->reference_node, f->reference_direction)) continue;
    if (found)
      fail_record(path, *f, "response and reference",
                  "must be those of one function only: record " + std::to_string(found->record) +
                      " is the same function type at the same response and reference",
                  "'" + dof_name(f->response_node, f->response_direction) + "' per '" +
                      dof_name(f->reference_node, f->reference_direction) + "'");
    found = f;
  }
  return found;
}

}  // namespace

FrfData frf_data_from_uff(const uff::File& file, const std::string& path, const UffFrfOptions& o,
                          std::vector<int>* response_orders) {
  check_options(o);
  std::vector<Dof> stations;
  for (std::size_t s = 0; s < o.stations.size(); ++s) {
    const auto& [name, text] = o.stations[s];
    const std::string field = "frf.stations." + name;
    stations.push_back(option_dof(text, o.source, field));
    for (std::size_t t = 0; t < s; ++t) {
      if (o.stations[t].first == name) fail_field(o.source, field, "must be given once", "a second " + quoted(text));
      if (stations[t].node == stations[s].node && stations[t].axis == stations[s].axis)
        fail_field(o.source, field, "must name a response no other station names (frf.stations." + o.stations[t].first + " is at it)",
                   quoted(text));
    }
  }
  const auto frfs = functions_of_type(file, kFrf);
  if (frfs.empty())
    throw InputError(one_line("UFF file '" + path + "': no frequency response function (dataset 58, function type 4) among its " +
                              std::to_string(file.functions.size()) + " functions"));
  const auto coherences = functions_of_type(file, kCoherence);
  const Dof ref = reference_of(frfs, path, o);
  const std::string ref_name = dof_name(ref.node, ref.direction());

  FrfData d;
  d.source = path;
  d.input = o.reference;
  d.estimator = "file";
  d.averages = o.averages;
  std::vector<int> orders;
  const uff::Function* first = nullptr;
  for (std::size_t s = 0; s < stations.size(); ++s) {
    const auto& [name, text] = o.stations[s];
    const Dof& st = stations[s];
    const uff::Function* f = one_at(path, frfs, st, ref);
    if (!f) {
      std::vector<std::string> there;
      for (const auto* g : frfs)
        if (ref.at(g->reference_node, g->reference_direction)) there.push_back(dof_name(g->response_node, g->response_direction));
      fail_field(o.source, "frf.stations." + name,
                 "must be the response of a frequency response function (function type 4) per " + ref_name + " in UFF file '" +
                     path + "', whose responses there are " + list(there),
                 quoted(text));
    }
    // The function: complex, per force, of a motion.
    if (!f->is_complex())
      fail_record(path, *f, "ordinate data type", "must be 5 or 6 (complex) for a frequency response function",
                  std::to_string(f->ordinate_type));
    const int order = response_order(f->ordinate.spec_type);
    if (order < 0)
      fail_record(path, *f, "ordinate specific data type", "must be 8 (displacement), 11 (velocity) or 12 (acceleration)",
                  std::to_string(f->ordinate.spec_type));
    if (f->denominator.spec_type != kForce)
      fail_record(path, *f, "ordinate denominator specific data type", "must be 13 (excitation force)",
                  std::to_string(f->denominator.spec_type));
    bool dropped = false;
    const std::vector<double> x = lines_of(path, *f, dropped);
    if (!first) {
      first = f;
      d.f_hz = x;
    } else {
      check_same_lines(path, *f, x, *first, d.f_hz);
    }
    const double factor = si_factor(path, file, *f) * st.sign * (f->response_direction < 0 ? -1 : 1) * ref.sign *
                          (f->reference_direction < 0 ? -1 : 1);
    // Its coherence, at the same response and reference.
    Dof response;
    response.node = f->response_node;
    response.axis = std::abs(f->response_direction);
    const uff::Function* c = one_at(path, coherences, response, ref);
    std::vector<double> gamma2;
    if (c) {
      if (c->is_complex())
        fail_record(path, *c, "ordinate data type", "must be 2 or 4 (real) for a coherence", std::to_string(c->ordinate_type));
      bool c_dropped = false;
      const std::vector<double> cx = lines_of(path, *c, c_dropped);
      check_same_lines(path, *c, cx, *f, x);
      gamma2.assign(c->re.begin() + (c_dropped ? 1 : 0), c->re.end());
    }
    const bool weighted_by_coherence = c && o.averages > 0;
    if (!weighted_by_coherence && o.relative_std == 0) {
      if (c)
        fail_field(o.source, "frf.averages",
                   "must be > 0 to weight station '" + name + "' by its coherence (" + record_of(path, *c) +
                       "), or frf.relative_std > 0",
                   "0");
      fail_field(o.source, "frf.relative_std",
                 "must be > 0: the file has no coherence (function type 6) for station '" + name + "' (" + record_of(path, *f) +
                     ") to weight it with frf.averages",
                 "0");
    }
    FrfData::Channel ch;
    ch.sensor = name;
    const std::size_t skip = dropped ? 1 : 0;
    for (std::size_t k = 0; k < x.size(); ++k) {
      const std::size_t point = k + skip + 1;
      const std::complex<double> h = factor * std::complex<double>(f->re[k + skip], f->im[k + skip]);
      const double mag = std::abs(h);
      if (!std::isfinite(mag) || mag > limits::kMaxMagnitude)
        fail_record(path, *f, "value " + std::to_string(point) + " (" + format_value(x[k]) + " Hz)",
                    "must be finite, of magnitude at most " + format_value(limits::kMaxMagnitude) + " in SI",
                    format_value(h.real()) + (h.imag() < 0 ? "" : "+") + format_value(h.imag()) + "i");
      double var = 0;
      if (c) {
        double g = gamma2[k];
        const bool bad = weighted_by_coherence ? !(g > 0) || g > 1 + 1e-9 : !(g >= 0) || g > 1 + 1e-9;
        if (bad)
          fail_record(path, *c, "coherence at point " + std::to_string(point) + " (" + format_value(x[k]) + " Hz)",
                      weighted_by_coherence ? "must be in (0, 1] to weight the FRF with frf.averages" : "must be in [0, 1]",
                      format_value(g));
        g = std::min(g, 1.0);
        ch.coherence.push_back(g);
        if (weighted_by_coherence) {
          var = (1 - g) / (g * o.averages) * mag * mag;
          if (!(var > 0))
            fail_record(path, *c, "coherence at point " + std::to_string(point) + " (" + format_value(x[k]) + " Hz)",
                        std::string("gives the value variance 0 (") + (mag == 0 ? "H = 0" : "coherence 1") +
                            "), which cannot weight it: state frf.relative_std (with frf.averages: 0) in " + o.source +
                            " to weight the values by their magnitude instead",
                        format_value(gamma2[k]));
        }
      }
      if (!weighted_by_coherence) {
        var = o.relative_std * mag * o.relative_std * mag;
        if (!(var > 0))
          fail_record(path, *f, "value " + std::to_string(point) + " (" + format_value(x[k]) + " Hz)",
                      "must not be 0: frf.relative_std times its magnitude gives it variance 0, which cannot weight it",
                      "0");
      }
      if (!std::isfinite(var))
        fail_record(path, *f, "value " + std::to_string(point) + " (" + format_value(x[k]) + " Hz)",
                    "must have a finite variance", format_value(var));
      ch.H.push_back(h);
      ch.variance.push_back(var);
    }
    d.channels.push_back(std::move(ch));
    orders.push_back(order);
  }
  if (response_orders) *response_orders = std::move(orders);
  return d;
}

// ---------------------------------------------------------------------------------------------
// Writing.

namespace {

// The most precise E-format of v that fits a 13-character field with a blank before it (7
// significant digits; fewer for a negative value or a 3-digit exponent), so that readers that
// split a line at blanks read it as well as those that cut it at fixed columns; and the value it
// reads back as.
std::pair<std::string, double> field13(double v) {
  for (int digits = 7; digits >= 1; --digits) {
    const std::string s = format("%13.*E", digits - 1, v);
    if (s.size() <= 13 && s[0] == ' ') return {s, std::strtod(s.c_str(), nullptr)};
  }
  return {format("%13.5E", v), v};  // not reached for a finite double
}

struct Abscissa {
  bool even = true;
  std::string min, increment;  // 13 characters each
};

// Even when min + k·increment, read back from the 13-character fields as the reader computes it,
// is within 5e-7 of every line: the rounding of each line written in 13 characters itself.
Abscissa abscissa_of(const std::vector<double>& f) {
  const std::size_t n = f.size();
  Abscissa a;
  const auto [m, m_read] = field13(f.front());
  a.min = m;
  if (n == 1) {
    a.increment = m;
    return a;
  }
  const double candidates[] = {(f.back() - f.front()) / static_cast<double>(n - 1), f[1] - f[0]};
  for (const double step : candidates) {
    const auto [d, d_read] = field13(step);
    bool ok = d_read > 0;
    for (std::size_t k = 0; k < n && ok; ++k) ok = std::abs(m_read + static_cast<double>(k) * d_read - f[k]) <= 5e-7 * f[k];
    if (ok) {
      a.increment = d;
      return a;
    }
  }
  a.even = false;
  a.min = a.increment = format("%13.5E", 0.0);
  return a;
}

std::string axis_line(int spec, int length_exp, int force_exp, const std::string& label, const std::string& unit) {
  return format("%10i%5i%5i%5i %-20s %-20s\n", spec, length_exp, force_exp, 0, label.c_str(), unit.c_str());
}

// The data lines: even, 4 values of 20 characters a line; uneven, each line's frequency in 13
// characters before its values (complex: one line a point; real: two points a line).
void put_values(std::string& out, const Abscissa& a, const std::vector<double>& f, const std::vector<double>& re,
                const std::vector<double>* im) {
  const std::size_t n = f.size();
  if (a.even) {
    std::vector<double> v;
    v.reserve(n * 2);
    for (std::size_t k = 0; k < n; ++k) {
      v.push_back(re[k]);
      if (im) v.push_back((*im)[k]);
    }
    for (std::size_t i = 0; i < v.size(); ++i) {
      out += format("%20.12E", v[i]);
      if (i % 4 == 3 || i + 1 == v.size()) out += '\n';
    }
    return;
  }
  for (std::size_t k = 0; k < n; ++k) {
    out += field13(f[k]).first + format("%20.12E", re[k]);
    if (im) out += format("%20.12E", (*im)[k]);
    if (im || k % 2 == 1 || k + 1 == n) out += '\n';
  }
}

std::string spec_label(int order) { return order == 0 ? "Displacement" : order == 1 ? "Velocity" : "Acceleration"; }

std::string spec_unit(int order, bool rotation) {
  const std::string base = rotation ? "rad" : "m";
  return order == 0 ? base : order == 1 ? base + "/s" : base + "/s^2";
}

}  // namespace

void write_uff_frf(const std::string& path, const FrfData& data,
                   const std::vector<std::pair<std::string, std::string>>& stations, const std::string& reference,
                   const std::vector<int>& response_orders) {
  const std::string where = "UFF file '" + path + "': cannot be written: ";
  auto refuse = [&](const std::string& what) { throw InputError(one_line(where + what)); };
  const std::vector<double>& f = data.f_hz;
  const std::size_t n = f.size();
  if (n == 0) refuse("the FRFs have no line");
  if (data.decay != 0)  // a reader would take them for H(iω)
    refuse("the FRFs are H(s) at s = " + format_value(data.decay) + " + iω (an exponential window), which a dataset 58 cannot say");
  if (static_cast<double>(n) > limits::kMaxSamples)
    refuse(std::to_string(n) + " lines, more than " + format_value(limits::kMaxSamples));
  for (std::size_t k = 0; k < n; ++k)
    if (!std::isfinite(f[k]) || !(f[k] > 0) || (k > 0 && !(f[k] > f[k - 1])))
      refuse("line " + std::to_string(k + 1) + " must be a frequency > 0 Hz above the one before, got " + format_value(f[k]));
  if (data.channels.empty()) refuse("no channel");
  if (response_orders.size() != data.channels.size())
    refuse("response orders must number " + std::to_string(data.channels.size()) + " (one per channel), got " +
           std::to_string(response_orders.size()));
  Dof ref;
  if (!reference.empty()) {
    const auto r = parse_dof(reference);
    if (!r) refuse(std::string("reference ") + kStationForm + ", got " + quoted(reference));
    ref = *r;
  }
  std::vector<Dof> at;
  for (std::size_t s = 0; s < data.channels.size(); ++s) {
    const auto& ch = data.channels[s];
    const std::string sensor = "sensor " + quoted(ch.sensor);
    bool printable = !ch.sensor.empty() && ch.sensor.size() <= 70;
    for (const unsigned char c : ch.sensor) printable = printable && c > 0x20 && c < 0x7f;
    if (!printable) refuse(sensor + ": a name for ID line 1 must be 1 to 70 printable ASCII characters without blanks");
    const auto it = std::find_if(stations.begin(), stations.end(), [&](const auto& p) { return p.first == ch.sensor; });
    if (it == stations.end()) refuse(sensor + " has no station (<node><sign><axis>)");
    const auto d = parse_dof(it->second);
    if (!d) refuse(sensor + ": station " + kStationForm + ", got " + quoted(it->second));
    for (std::size_t t = 0; t < s; ++t)
      if (at[t].node == d->node && at[t].axis == d->axis)
        refuse(sensor + " is at the response of sensor " + quoted(data.channels[t].sensor) + " (" + quoted(it->second) +
               "): one FRF per response and reference");
    at.push_back(*d);
    if (response_orders[s] < 0 || response_orders[s] > 2)
      refuse(sensor + ": response order must be 0 (displacement), 1 (velocity) or 2 (acceleration), got " +
             std::to_string(response_orders[s]));
    if (ch.H.size() != n)
      refuse(sensor + ": " + std::to_string(ch.H.size()) + " values for " + std::to_string(n) + " lines");
    for (std::size_t k = 0; k < n; ++k)
      if (!std::isfinite(ch.H[k].real()) || !std::isfinite(ch.H[k].imag()))
        refuse(sensor + ": value at line " + std::to_string(k + 1) + " must be finite, got " + format_value(ch.H[k].real()) + ", " +
               format_value(ch.H[k].imag()));
    if (!ch.coherence.empty() && ch.coherence.size() != n)
      refuse(sensor + ": " + std::to_string(ch.coherence.size()) + " coherence values for " + std::to_string(n) + " lines");
    for (std::size_t k = 0; k < ch.coherence.size(); ++k)
      if (!(ch.coherence[k] >= 0 && ch.coherence[k] <= 1))
        refuse(sensor + ": coherence at line " + std::to_string(k + 1) + " must be in [0, 1], got " + format_value(ch.coherence[k]));
  }

  const Abscissa a = abscissa_of(f);
  std::string out;
  out += format("%6i\n%6i\n", -1, 151);
  out += "scoleid FRF\nfrequency response functions\nscoleid\n";
  out += format("%10s%10s%10i%10i%10i\n", "", "", 0, 0, 0);
  out += format("%10s%10s\n", "", "");
  out += "scoleid\n";
  out += format("%10s%10s\n", "", "");
  out += format("%6i\n", -1);
  out += format("%6i\n%6i\n", -1, 164);
  out += format("%10i%-20s%10i\n", 1, "SI: Meter (newton)", 2);
  out += format("%25.17E%25.17E%25.17E\n%25.17E\n", 1.0, 1.0, 1.0, 273.15);
  out += format("%6i\n", -1);
  int function_id = 0;
  for (std::size_t s = 0; s < data.channels.size(); ++s) {
    const auto& ch = data.channels[s];
    const int order = response_orders[s];
    const bool rotation = at[s].axis >= 4;
    std::vector<double> re(n), im(n);
    for (std::size_t k = 0; k < n; ++k) {
      re[k] = ch.H[k].real();
      im[k] = ch.H[k].imag();
    }
    auto header = [&](int type, int ordinate_type, const std::string& id1, const std::string& id2) {
      out += format("%6i\n%6i\n", -1, 58);
      out += id1 + "\n" + id2 + "\nNONE\nNONE\nNONE\n";
      out += format("%5i%10i%5i%10i %-10s%10i%4i %-10s%10i%4i\n", type, ++function_id, 0, 0, "NONE", at[s].node,
                    at[s].direction(), "NONE", ref.node, ref.direction());
      out += format("%10i%10zu%10i", ordinate_type, n, a.even ? 1 : 0) + a.min + a.increment + format("%13.5E\n", 0.0);
      out += axis_line(kFrequency, 0, 0, "Frequency", "Hz");
    };
    header(kFrf, 6, ch.sensor, "Frequency Response Function");
    out += axis_line(order == 0 ? kDisplacement : order == 1 ? kVelocity : kAcceleration, rotation ? 0 : 1, 0, spec_label(order),
                     spec_unit(order, rotation));
    out += axis_line(kForce, 0, 1, "Force", "N");
    out += axis_line(0, 0, 0, "NONE", "NONE");
    put_values(out, a, f, re, &im);
    out += format("%6i\n", -1);
    if (ch.coherence.empty()) continue;
    header(kCoherence, 4, ch.sensor + " coherence", "Coherence");
    out += axis_line(0, 0, 0, "Coherence", "NONE");
    out += axis_line(0, 0, 0, "NONE", "NONE");
    out += axis_line(0, 0, 0, "NONE", "NONE");
    put_values(out, a, f, ch.coherence, nullptr);
    out += format("%6i\n", -1);
  }
  try {
    write_text_atomic(path, out);
  } catch (const std::runtime_error& e) {
    refuse(e.what());
  }
}

}  // namespace scoleid::io
