#include "scoleid/io/validation.h"

#include <cmath>
#include <cstdio>
#include <set>

#include "scoleid/io/error.h"
#include "scoleid/io/limits.h"
#include "scoleid/io/scenario_fields.h"
#include "scoleid/io/structure_parameters.h"
#include "structure_kinds.h"

namespace scoleid::io {

bool valid_name(const std::string& n) {
  if (n.empty() || n.size() > limits::kMaxNameLength || n == "t") return false;
  auto word = [](char c) {
    return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_';
  };
  if (!word(n[0])) return false;
  for (char c : n)
    if (!word(c) && c != '.' && c != '-') return false;
  return true;
}

void check_name(const std::string& source, const std::string& field, const std::string& name) {
  if (valid_name(name)) return;
  fail_field(source, field,
             "must be 1-" + std::to_string(limits::kMaxNameLength) +
                 " characters from [A-Za-z0-9_.-], starting with a letter, digit or '_', and not 't'",
             "'" + one_line(shorten(name)) + "'");
}

std::string windows1252_to_utf8(const std::string& s) {
  if (first_invalid_utf8(s) == std::string::npos) return s;
  static const char16_t k80[32] = {0x20AC, 0xFFFD, 0x201A, 0x0192, 0x201E, 0x2026, 0x2020, 0x2021, 0x02C6, 0x2030, 0x0160,
                                   0x2039, 0x0152, 0xFFFD, 0x017D, 0xFFFD, 0xFFFD, 0x2018, 0x2019, 0x201C, 0x201D, 0x2022,
                                   0x2013, 0x2014, 0x02DC, 0x2122, 0x0161, 0x203A, 0x0153, 0xFFFD, 0x017E, 0x0178};
  std::string out;
  for (unsigned char c : s) {
    const unsigned cp = c < 0x80 ? c : c < 0xA0 ? static_cast<unsigned>(k80[c - 0x80]) : c;
    if (cp < 0x80) {
      out += static_cast<char>(cp);
    } else if (cp < 0x800) {
      out += static_cast<char>(0xC0 | (cp >> 6));
      out += static_cast<char>(0x80 | (cp & 0x3F));
    } else {
      out += static_cast<char>(0xE0 | (cp >> 12));
      out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
      out += static_cast<char>(0x80 | (cp & 0x3F));
    }
  }
  return out;
}

std::size_t first_invalid_utf8(const std::string& s) {
  const auto* p = reinterpret_cast<const unsigned char*>(s.data());
  const std::size_t n = s.size();
  std::size_t i = 0;
  while (i < n) {
    const unsigned char c = p[i];
    if (c < 0x80) {
      ++i;
      continue;
    }
    std::size_t len = 0;
    unsigned lo = 0x80, hi = 0xBF;  // allowed range of the second byte
    if (c >= 0xC2 && c <= 0xDF) len = 2;
    else if (c == 0xE0) { len = 3; lo = 0xA0; }
    else if ((c >= 0xE1 && c <= 0xEC) || c == 0xEE || c == 0xEF) len = 3;
    else if (c == 0xED) { len = 3; hi = 0x9F; }  // no surrogates
    else if (c == 0xF0) { len = 4; lo = 0x90; }
    else if (c >= 0xF1 && c <= 0xF3) len = 4;
    else if (c == 0xF4) { len = 4; hi = 0x8F; }  // nothing above U+10FFFF
    else return i;
    if (i + len > n) return i;
    if (p[i + 1] < lo || p[i + 1] > hi) return i;
    for (std::size_t k = 2; k < len; ++k)
      if (p[i + k] < 0x80 || p[i + k] > 0xBF) return i;
    i += len;
  }
  return std::string::npos;
}

void check_utf8(const std::string& text, const std::string& what) {
  const std::size_t at = first_invalid_utf8(text);
  if (at == std::string::npos) return;
  std::size_t line = 1;
  for (std::size_t i = 0; i < at; ++i)
    if (text[i] == '\n') ++line;
  char hex[8];
  std::snprintf(hex, sizeof hex, "0x%02X", static_cast<unsigned char>(text[at]));
  throw InputError(what + ": byte " + std::to_string(at + 1) + " (line " + std::to_string(line) + ", " + hex +
                   ") is not valid UTF-8");
}

void check_magnitude(const std::string& source, const std::string& field, double v) {
  if (!std::isfinite(v)) fail_field(source, field, "must be a finite number", format_value(v));
  const double a = std::abs(v);
  if (a != 0.0 && (a < limits::kMinMagnitude || a > limits::kMaxMagnitude))
    fail_field(source, field,
               "must be 0 or of magnitude between " + format_value(limits::kMinMagnitude) + " and " +
                   format_value(limits::kMaxMagnitude),
               format_value(v));
}

double sample_count(double duration, double interval) {
  if (!(interval > 0) || !(duration >= 0)) return INFINITY;
  return std::floor(duration / interval + 1e-9) + 1.0;
}

// A sensor kind the structure's models read (types.h, reads).
void check_sensor_kind(const Scenario& sc, const std::string& field, SensorKind kind) {
  if (reads(sc.structure, kind)) return;
  const std::string list = sensor_kinds_read_by(sc.structure);
  std::string readers;
  for (const auto& [st, name] : Names<Structure>::rows)
    if (reads(st, kind)) readers += (readers.empty() ? "" : ", ") + std::string(name);
  fail_field(sc.source, field,
             "is not read on a " + std::string(to_string(sc.structure)) + " structure (it reads " + list + ")" +
                 (readers.empty() ? "" : "; it is read with structure: " + readers),
             quoted(kind));
}

void check_location(const Scenario& sc, const std::string& field, Site at, double loc, const std::string& source) {
  if (!has_station(at)) return;
  // A frame's height is a sum of storey heights, which may round below the top floor's height as
  // written (0.7 + 0.1 < 0.8): its top is met within 1e-12 of the height.
  const double L = kind_table(sc.structure).length(sc) * (at == Site::Frame ? 1.0 + 1e-12 : 1.0);
  if (!(loc >= 0.0 && loc <= L))
    fail_field(source.empty() ? sc.source : source, field,
               "must lie on the " + std::string(to_string(at)) + " [0, " + format_value(L) + "]", format_value(loc));
}

namespace {
// The physical quantities an estimated name sets: itself, or in the paper's form (the equation
// divided by ρA, docs/theory.md §2.3) q1 = EI/ρA the EI group, q2 = 1/ρA ρA and, with q1 and q3
// held, EI and c_kv too, q3 = c_kv/ρA c_kv.
std::vector<std::string> quantities_set_by(const std::string& name, bool paper) {
  if (!paper) return {name};
  if (name == "q1") return {"EI"};
  if (name == "q2") return {"rho_A", "EI", "c_kv"};
  if (name == "q3") return {"c_kv"};
  return {name};
}

// The estimated parameter that sets the number at `path` ("" when none does): each quantity an
// estimated parameter sets is moved in a copy of the scenario, and the one that moves the number
// names it.
std::string estimated_by(const Scenario& sc, const std::string& path) {
  Scenario probe = sc;
  const double* here = numeric_field(probe, path);
  if (!here) return "";
  const double before = *here;
  const bool paper = sc.identification.parameterization == "paper";
  // Two values, so that one differs from the parameter's own (a name such as SCOLE's EI, which
  // sets both bending planes, has no single value of its own).
  for (const auto& name : sc.identification.estimate)
    for (const auto& quantity : quantities_set_by(name, paper))
      for (const double to : {1.0, 2.0}) {
        Scenario moved = sc;
        set_structure_parameters(moved, {{quantity, to}});
        const double* there = numeric_field(moved, path);
        if (there && *there != before) return name;
      }
  return "";
}

// identification.uncertain: a field of this scenario, not estimated, its tolerance below the value
// of a quantity that cannot be negative; a switch with the other setting.
void check_uncertain(const Scenario& sc) {
  Scenario probe = sc;
  for (const auto& u : sc.identification.uncertain) {
    const std::string field = "identification.uncertain." + u.field;
    if (u.is_switch) {
      const bool* b = bool_field(probe, u.field);
      if (!b) fail_field(sc.source, field, "names no switch of this scenario (switches: scole.bending_rotary_inertia)", "'" + u.field + "'");
      if (*b == u.alternative)
        fail_field(sc.source, field, "must name the alternative to the model's setting", u.alternative ? "true" : "false");
    } else if (const double* v = numeric_field(probe, u.field); !v) {
      std::string known;
      for (const auto& p : field_paths(probe))
        if (p != "scole.bending_rotary_inertia") known += (known.empty() ? "" : ", ") + p;
      fail_field(sc.source, field, "names no number of this scenario (known: " + known + ")", "'" + u.field + "'");
    } else if (const std::string by = estimated_by(sc, u.field); !by.empty()) {
      // The interval's consider term moves a quantity the fit holds fixed; an estimated one the
      // fit sets itself.
      fail_field(sc.source, field,
                 "is estimated (identification.estimate names " + by + "): a quantity is estimated or declared uncertain, not both",
                 format_value(u.tolerance));
    } else if (!signed_field(u.field) && *v > 0 && !(u.tolerance < *v)) {
      // The interval's consider term is a first-order shift: a tolerance as large as the value
      // of a quantity that cannot be negative says the quantity is unknown, not uncertain.
      fail_field(sc.source, field,
                 "must be smaller than the value it is a tolerance of (" + format_value(*v) +
                     "): a quantity known no better than that is unknown (estimate it instead)",
                 format_value(u.tolerance));
    }
  }
}

// Every input's and sensor's station lies on the structure and every sensor's kind is read on it;
// then the kind's own checks of sites, directions and sections.
void check_sites(const Scenario& sc) {
  for (std::size_t i = 0; i < sc.inputs.size(); ++i)
    check_location(sc, "inputs[" + std::to_string(i) + "].location", sc.inputs[i].at, sc.inputs[i].location);
  for (std::size_t k = 0; k < sc.sensors.size(); ++k) {
    const std::string f = "sensors[" + std::to_string(k) + "]";
    check_sensor_kind(sc, f + ".kind", sc.sensors[k].kind);
    check_location(sc, f + ".location", sc.sensors[k].at, sc.sensors[k].location);
  }
  kind_table(sc.structure).check(sc);
}
}  // namespace

void validate_scenario(const Scenario& sc) {
  const std::string& src = sc.source;
  check_name(src, "name", sc.name);
  std::set<std::string> names;
  for (std::size_t i = 0; i < sc.inputs.size(); ++i) {
    const std::string f = "inputs[" + std::to_string(i) + "].name";
    check_name(src, f, sc.inputs[i].name);
    if (!names.insert(sc.inputs[i].name).second) fail_field(src, f, "must be unique", "'" + sc.inputs[i].name + "'");
  }
  for (std::size_t i = 0; i < sc.sensors.size(); ++i) {
    const std::string f = "sensors[" + std::to_string(i) + "].name";
    check_name(src, f, sc.sensors[i].name);
    if (!names.insert(sc.sensors[i].name).second)
      fail_field(src, f, "must be unique among inputs and sensors", "'" + sc.sensors[i].name + "'");
  }
  check_sites(sc);
  check_uncertain(sc);
  const double columns = 1.0 + static_cast<double>(sc.inputs.size() + sc.sensors.size());
  auto check_record = [&](const std::string& field, double interval) {
    const double n = sample_count(sc.simulation.duration, interval);
    if (!(n <= limits::kMaxSamples))
      fail_field(src, field,
                 "gives " + format_value(n) + " samples over simulation.duration " + format_value(sc.simulation.duration) +
                     ", more than the limit of " + format_value(limits::kMaxSamples),
                 format_value(interval));
    if (!(n * columns <= limits::kMaxRecordValues))
      fail_field(src, field,
                 "gives " + format_value(n) + " samples x " + format_value(columns) + " columns, more than the limit of " +
                     format_value(limits::kMaxRecordValues) + " values",
                 format_value(interval));
  };
  check_record("simulation.sample_interval", sc.simulation.sample_interval);
  if (const double n = sample_count(sc.simulation.duration, sc.simulation.sample_interval); n < 3)
    fail_field(src, "simulation.sample_interval",
               "gives " + format_value(n) + " samples over simulation.duration " + format_value(sc.simulation.duration) +
                   ": at least 3 are needed",
               format_value(sc.simulation.sample_interval));
  if (sc.truth.output_interval > 0) check_record("truth.output_interval", sc.truth.output_interval);
  if (sc.truth.output_interval > sc.simulation.duration)
    fail_field(src, "truth.output_interval", "must not exceed simulation.duration (" + format_value(sc.simulation.duration) + ")",
               format_value(sc.truth.output_interval));
  if (sc.truth.anti_alias_hz > 0) {
    const double dt = sc.truth.output_interval > 0 ? sc.truth.output_interval : sc.simulation.sample_interval;
    if (!(sc.truth.anti_alias_hz < 0.5 / dt))
      fail_field(src, "truth.anti_alias_hz",
                 "must lie below the output's Nyquist frequency " + format_value(0.5 / dt) + " Hz (sample interval " +
                     format_value(dt) + " s)",
                 format_value(sc.truth.anti_alias_hz));
    // The filter runs on samples 8 times denser than the output's (model/truth_run.cpp).
    if (!(sample_count(sc.simulation.duration, dt / 8) <= limits::kMaxSamples))
      fail_field(src, "truth.anti_alias_hz",
                 "samples the record 8 times faster inside: more than the limit of " + format_value(limits::kMaxSamples) +
                     " samples",
                 format_value(sc.truth.anti_alias_hz));
  }
  if (sc.truth.segments < 2 || sc.truth.segments > limits::kMaxSegments)
    fail_field(src, "truth.segments", "must be an integer in [2, " + std::to_string(limits::kMaxSegments) + "]",
               std::to_string(sc.truth.segments));
  // Below 1e-14 no integrator meets a relative error per step in double precision (Simbody's stop
  // at the first step with "unable to advance time").
  if (!(sc.truth.accuracy >= 1e-14 && sc.truth.accuracy < 1))
    fail_field(src, "truth.accuracy", "must be in [1e-14, 1) (a smaller error per step is below double precision)",
               format_value(sc.truth.accuracy));
  // A servo lag longer than the record leaves the actuators still throughout: no actuator at all.
  if (sc.structure == Structure::Scole) {
    const double lag = sc.truth.overrides.empty() ? sc.scole.actuator_lag : truth_scenario(sc).scole.actuator_lag;
    if (!(lag < sc.simulation.duration))
      fail_field(src, sc.scole.actuator_lag == lag ? "scole.actuator_lag" : "truth.overrides.scole.actuator_lag",
                 "must be shorter than simulation.duration (" + format_value(sc.simulation.duration) +
                     "): the actuators would not move within the record",
                 format_value(lag));
  }
  const auto& id = sc.identification;
  if (id.model == Model::Nonlinear && sc.structure != Structure::Scole)
    fail_field(src, "identification.model", "'nonlinear' is a SCOLE model (structure: scole)", "'nonlinear'");
  // One weight per estimated parameter (each name of identification.estimate is one).
  if (!id.steepest_weights.empty() && id.steepest_weights.size() != id.estimate.size())
    fail_field(src, "identification.steepest_weights",
               "must hold one weight per estimated parameter (" + std::to_string(id.estimate.size()) + ")",
               std::to_string(id.steepest_weights.size()) + " values");
  if (id.elements < 1 || id.elements > limits::kMaxElements)
    fail_field(src, "identification.elements", "must be an integer in [1, " + std::to_string(limits::kMaxElements) + "]",
               std::to_string(id.elements));
  if (id.data_elements < 0 || id.data_elements > limits::kMaxDataElements)
    fail_field(src, "identification.data_elements",
               "must be an integer in [0, " + std::to_string(limits::kMaxDataElements) + "]", std::to_string(id.data_elements));
  if (!(id.rtol > 0 && id.rtol < 1)) fail_field(src, "identification.rtol", "must be in (0, 1)", format_value(id.rtol));
  if (id.max_iterations < 0)
    fail_field(src, "identification.max_iterations", "must be >= 0", std::to_string(id.max_iterations));
  if (id.time_step > 0) {
    const double steps = sc.simulation.duration / id.time_step;
    if (!(steps <= limits::kMaxSteps))
      fail_field(src, "identification.time_step",
                 "gives " + format_value(std::ceil(steps)) + " steps over simulation.duration " +
                     format_value(sc.simulation.duration) + ", more than the limit of " + format_value(limits::kMaxSteps),
                 format_value(id.time_step));
  }
}

namespace {
// The largest prefix length <= n that does not end inside a UTF-8 sequence.
std::size_t utf8_boundary(const std::string& s, std::size_t n) {
  while (n > 0 && n < s.size() && (static_cast<unsigned char>(s[n]) & 0xC0) == 0x80) --n;
  return n;
}
}  // namespace

std::string shorten(const std::string& value, std::size_t keep) {
  if (value.size() <= keep + 40) return value;
  return value.substr(0, utf8_boundary(value, keep)) + "... (" + std::to_string(value.size()) + " characters)";
}

void check_fe_reproduces_truth(const std::string& source, const Scenario& truth_sc, const std::string& why) {
  if (truth_sc.structure == Structure::Scole && truth_sc.scole.actuator_lag > 0)
    fail_field(source, "truth.overrides.scole.actuator_lag", "is a servo lag of the Simbody truth only: " + why,
               format_value(truth_sc.scole.actuator_lag));
}

std::string one_line(const std::string& message) {
  // A message that echoes a huge name or cell is cut in the middle: its head names the file and
  // the field, its tail the requirement and the value's end.
  constexpr std::size_t kHead = 400, kTail = 160;
  std::string cut = message;
  if (message.size() > kHead + kTail + 80) {
    const std::size_t head = utf8_boundary(message, kHead);
    std::size_t tail = message.size() - kTail;
    while (tail < message.size() && (static_cast<unsigned char>(message[tail]) & 0xC0) == 0x80) ++tail;
    cut = message.substr(0, head) + " ... (" + std::to_string(tail - head) + " characters left out) ... " + message.substr(tail);
  }
  const std::string& m = cut;
  std::string out;
  out.reserve(m.size());
  // Trailing line breaks carry nothing.
  std::size_t end = m.size();
  while (end > 0 && (m[end - 1] == '\n' || m[end - 1] == '\r')) --end;
  for (std::size_t i = 0; i < end; ++i) {
    const unsigned char c = static_cast<unsigned char>(m[i]);
    if (c == '\n') out += "\\n";
    else if (c == '\r') out += "\\r";
    else if (c == '\t') out += "\\t";
    else if (c < 0x20 || c == 0x7F) {
      char b[8];
      std::snprintf(b, sizeof b, "\\x%02X", c);
      out += b;
    } else if (c == 0xC2 && i + 1 < end && static_cast<unsigned char>(m[i + 1]) >= 0x80 &&
               static_cast<unsigned char>(m[i + 1]) <= 0x9F) {
      // A C1 control (U+0080..U+009F, UTF-8 C2 80..C2 9F): U+0085 is a line break to many terminals.
      char b[10];
      std::snprintf(b, sizeof b, "\\u%04X", static_cast<unsigned char>(m[i + 1]));
      out += b;
      ++i;
    } else {
      out += static_cast<char>(c);
    }
  }
  return out;
}

}  // namespace scoleid::io
