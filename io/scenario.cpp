#include "scoleid/io/scenario.h"
#include "scoleid/io/scenario_fields.h"
#include "scoleid/io/structure_parameters.h"
#include "scoleid/io/scenario_schema.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <vector>
#include <sstream>

#include "scoleid/io/error.h"
#include "scoleid/io/input_file.h"
#include "scoleid/io/limits.h"
#include "scoleid/io/number.h"
#include "scoleid/io/validation.h"
#include "structure_kinds.h"

namespace scoleid::io {

std::vector<std::pair<const char*, double PointElement::*>> point_element_fields() {
  return {{"mass", &PointElement::mass},
          {"inertia", &PointElement::inertia},
          {"k_w", &PointElement::k_w},
          {"k_theta", &PointElement::k_theta},
          {"c_w", &PointElement::c_w},
          {"c_theta", &PointElement::c_theta},
          {"lumped_mass", &PointElement::lumped_mass},
          {"lumped_k", &PointElement::lumped_k},
          {"lumped_c", &PointElement::lumped_c},
          {"lumped_k_ground", &PointElement::lumped_k_ground}};
}

bool attachment_only_field(const std::string& key) {
  return key == "mass" || key == "inertia" || key.rfind("lumped_", 0) == 0;
}

bool displacement_field(const std::string& key) {
  return key == "mass" || key == "k_w" || key == "c_w" || key.rfind("lumped_", 0) == 0;
}

std::string point_element_parameter(const std::string& group, const PointElement& e, const char* field) {
  return group + "." + e.name + "." + field;
}

const char* to_string(EndCondition e) {
  switch (e) {
    case EndCondition::Pinned: return "pinned";
    case EndCondition::Clamped: return "clamped";
    case EndCondition::Free: return "free";
  }
  return "?";
}

namespace {

// The live ScenarioFieldRecorder's set on this thread (scenario_schema.h), or none.
thread_local std::set<std::string>* recorded_fields = nullptr;

// Notes a field's path in the recorder's set, list indices written `[]`.
void note_field(const std::string& path) {
  std::string p;
  for (std::size_t i = 0; i < path.size(); ++i) {
    p += path[i];
    std::size_t j = i + 1;
    while (path[i] == '[' && j < path.size() && path[j] >= '0' && path[j] <= '9') ++j;
    if (j > i + 1 && j < path.size() && path[j] == ']') i = j - 1;
  }
  recorded_fields->insert(p);
}

// Reads typed fields from a YAML map, naming `source` and the dotted field path on any error,
// and rejects keys the schema does not know (a typo must not silently fall back to a default).
class Reader {
public:
  Reader(const YAML::Node& node, std::string source, std::string path)
      : node_(node), source_(std::move(source)), path_(std::move(path)) {
    if (node_ && !node_.IsNull() && !node_.IsMap())
      fail_field(source_, path_.empty() ? "document" : path_, "must be a map", "a " + kind(node_));
  }
  ~Reader() noexcept(false) {
    if (std::uncaught_exceptions() == 0) check_unknown();
  }
  Reader(const Reader&) = delete;
  Reader& operator=(const Reader&) = delete;

  bool has(const std::string& key) {
    seen_.insert(key);
    if (recorded_fields) note_field(field(key));
    return node_ && node_.IsMap() && node_[key] && !node_[key].IsNull();
  }
  // The field holds exactly this text (a keyword such as "auto" where a number may stand).
  bool is_scalar(const std::string& key, const std::string& text) {
    return has(key) && node_[key].IsScalar() && node_[key].Scalar() == text;
  }
  YAML::Node child(const std::string& key) {
    seen_.insert(key);
    if (recorded_fields) note_field(field(key));
    return node_ && node_.IsMap() ? node_[key] : YAML::Node();
  }
  std::string field(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }
  const std::string& source() const { return source_; }

  double num(const std::string& key, double dflt) {
    if (!has(key)) return dflt;
    return as_number(node_[key], field(key));
  }
  double positive(const std::string& key, double dflt) {
    const double v = num(key, dflt);
    if (!(v > 0.0)) fail_field(source_, field(key), "must be > 0", format_value(v));
    return v;
  }
  double nonneg(const std::string& key, double dflt) {
    const double v = num(key, dflt);
    if (!(v >= 0.0)) fail_field(source_, field(key), "must be >= 0", format_value(v));
    return v;
  }
  int integer(const std::string& key, int dflt, int lo, int hi) {
    if (!has(key)) return dflt;
    const double v = as_number(node_[key], field(key));
    if (v != std::floor(v) || v < lo || v > hi)
      fail_field(source_, field(key),
                 "must be an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]",
                 format_value(v));
    return static_cast<int>(v);
  }
  std::string str(const std::string& key, const std::string& dflt) {
    if (!has(key)) return dflt;
    const YAML::Node n = node_[key];
    if (!n.IsScalar()) fail_field(source_, field(key), "must be a string", "a " + kind(n));
    return n.as<std::string>();
  }
  bool boolean(const std::string& key, bool dflt) {
    if (!has(key)) return dflt;
    const YAML::Node n = node_[key];
    if (n.IsScalar()) {  // YAML 1.2 core schema booleans only (a "yes" or "1" is refused)
      const std::string v = n.Scalar();
      if (v == "true" || v == "True" || v == "TRUE") return true;
      if (v == "false" || v == "False" || v == "FALSE") return false;
    }
    fail_field(source_, field(key), "must be true or false", n.IsScalar() ? kind(n) : "a " + kind(n));
  }
  std::string choice(const std::string& key, const std::string& dflt,
                     const std::vector<std::string>& allowed) {
    const std::string v = str(key, dflt);
    for (const auto& a : allowed)
      if (a == v) return v;
    std::string list;
    for (const auto& a : allowed) list += (list.empty() ? "" : "|") + a;
    fail_field(source_, field(key), "must be one of " + list, "'" + v + "'");
  }
  // A closed choice (io/types.h): its name in the file, the value inside.
  template <class E>
  E choice_of(const std::string& key, E dflt) {
    const std::string v = str(key, to_string(dflt));
    if (const auto e = parse<E>(v)) return *e;
    fail_field(source_, field(key), "must be one of " + names_joined<E>(), "'" + v + "'");
  }
  // The same, among some of the type's values only (listed in the message in the order given).
  template <class E>
  E choice_among(const std::string& key, E dflt, const std::vector<E>& allowed) {
    const std::string v = str(key, to_string(dflt));
    std::string list;
    for (const E a : allowed) {
      if (v == to_string(a)) return a;
      list += (list.empty() ? "" : "|") + std::string(to_string(a));
    }
    fail_field(source_, field(key), "must be one of " + list, "'" + v + "'");
  }
  std::vector<double> numbers(const std::string& key, const std::vector<double>& dflt) {
    if (!has(key)) return dflt;
    const YAML::Node n = node_[key];
    std::vector<double> out;
    if (n.IsScalar()) {
      out.push_back(as_number(n, field(key)));
    } else if (n.IsSequence()) {
      for (std::size_t i = 0; i < n.size(); ++i)
        out.push_back(as_number(n[i], field(key) + "[" + std::to_string(i) + "]"));
    } else {
      fail_field(source_, field(key), "must be a number or a list of numbers", "a " + kind(n));
    }
    return out;
  }
  std::vector<std::string> strings(const std::string& key) {
    std::vector<std::string> out;
    if (!has(key)) return out;
    const YAML::Node n = node_[key];
    if (n.IsScalar()) {
      out.push_back(n.as<std::string>());
    } else if (n.IsSequence()) {
      for (std::size_t i = 0; i < n.size(); ++i) {
        if (!n[i].IsScalar())
          fail_field(source_, field(key) + "[" + std::to_string(i) + "]", "must be a string",
                     "a " + kind(n[i]));
        out.push_back(n[i].as<std::string>());
      }
    } else {
      fail_field(source_, field(key), "must be a string or a list of strings", "a " + kind(n));
    }
    return out;
  }

  double as_number(const YAML::Node& n, const std::string& f) const {
    if (!n.IsScalar()) fail_field(source_, f, "must be a number", "a " + kind(n));
    const std::string text = n.Scalar();
    const std::string low = lower(text);
    if (low == "nan" || low == ".nan" || low == "inf" || low == ".inf" || low == "-.inf" ||
        low == "-inf" || low == "+inf")
      fail_field(source_, f, "must be a finite number", "'" + text + "'");
    double v = 0.0;
    if (!parse_decimal(text, v)) fail_field(source_, f, "must be a decimal number", "'" + text + "'");
    if (!std::isfinite(v)) fail_field(source_, f, "must be a finite number", "'" + text + "'");
    check_magnitude(source_, f, v);
    return v;
  }

  static std::string kind(const YAML::Node& n) {
    if (n.IsSequence()) return std::string("list");
    if (n.IsMap()) return std::string("map");
    if (n.IsNull()) return std::string("null");
    return "'" + n.Scalar() + "'";
  }

private:
  static std::string lower(std::string s) {
    for (auto& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return s;
  }
  // Levenshtein distance of two keys (short strings), for "did you mean".
  static std::size_t distance(const std::string& a, const std::string& b) {
    std::vector<std::size_t> row(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
      std::size_t diag = row[0];
      row[0] = i;
      for (std::size_t j = 1; j <= b.size(); ++j) {
        const std::size_t up = row[j];
        row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
        diag = up;
      }
    }
    return row[b.size()];
  }
  // An unknown key is refused with the fields known here (those this map's parser asked for) and
  // the nearest of them when it is within two edits.
  void check_unknown() const {
    if (!node_ || !node_.IsMap()) return;
    for (const auto& kv : node_) {
      const std::string key = kv.first.as<std::string>();
      if (seen_.count(key)) continue;
      std::string known, nearest;
      std::size_t best = 3;
      for (const auto& k : seen_) {
        known += (known.empty() ? "" : ", ") + k;
        const std::size_t d = distance(lower(key), lower(k));
        if (d < best) best = d, nearest = k;
      }
      fail_field(source_, field(key),
                 "is not a known field (" + (nearest.empty() ? std::string() : "did you mean '" + nearest + "'? ") + "known here: " + known + ")",
                 "'" + key + "'");
    }
  }

  YAML::Node node_;
  std::string source_, path_;
  std::set<std::string> seen_;
};

EndCondition parse_end(Reader& r, const std::string& key, EndCondition dflt) {
  const std::string v = r.choice(key, to_string(dflt), {"pinned", "clamped", "free"});
  if (v == "pinned") return EndCondition::Pinned;
  if (v == "clamped") return EndCondition::Clamped;
  return EndCondition::Free;
}

SignalTerm parse_signal_term(const YAML::Node& n, const std::string& source, const std::string& path) {
  Reader r(n, source, path);
  SignalTerm s;
  const std::string type = r.choice("type", "step",
                                    {"step", "pulse", "bangbang", "sine", "chirp", "haversine", "multisine", "table"});
  s.amplitude = r.num("amplitude", 0.0);
  s.t0 = r.num("t0", 0.0);
  if (type == "step") {
    s.type = SignalTerm::Type::Step;
  } else if (type == "pulse" || type == "bangbang" || type == "haversine") {
    s.type = type == "pulse" ? SignalTerm::Type::Pulse
             : type == "bangbang" ? SignalTerm::Type::BangBang : SignalTerm::Type::Haversine;
    s.width = r.positive("width", 0.0);
  } else if (type == "sine") {
    s.type = SignalTerm::Type::Sine;
    s.f0 = r.positive("frequency", 0.0);
    s.phase = r.num("phase", 0.0);
    s.duration = r.nonneg("duration", 0.0);
  } else if (type == "multisine") {
    s.type = SignalTerm::Type::Multisine;
    s.width = r.positive("period", 0.0);
    s.f0 = r.nonneg("f0", 0.0);
    s.f1 = r.positive("f1", 0.0);
    s.duration = r.nonneg("duration", 0.0);
    if (multisine_lines(s).empty())
      fail_field(source, r.field("f1"), "must leave at least one harmonic k/period (k >= 1) in [f0, f1]", format_value(s.f1));
    if (multisine_lines(s).size() > 100000)
      fail_field(source, r.field("period"), "gives more than 100000 lines in [f0, f1]", format_value(s.width));
  } else if (type == "chirp") {
    s.type = SignalTerm::Type::Chirp;
    s.f0 = r.nonneg("f0", 0.0);
    s.f1 = r.nonneg("f1", 0.0);
    s.duration = r.positive("duration", 0.0);
  } else {
    s.type = SignalTerm::Type::Table;
    s.times = r.numbers("times", {});
    s.values = r.numbers("values", {});
    if (s.times.empty() || s.times.size() != s.values.size())
      fail_field(source, r.field("values"), "must have one value per entry of times (" +
                                                std::to_string(s.times.size()) + ")",
                 std::to_string(s.values.size()) + " values");
    for (std::size_t i = 1; i < s.times.size(); ++i)
      if (!(s.times[i] > s.times[i - 1]))
        fail_field(source, r.field("times") + "[" + std::to_string(i) + "]",
                   "must be increasing", format_value(s.times[i]));
  }
  return s;
}

Signal parse_signal(const YAML::Node& n, const std::string& source, const std::string& path) {
  std::vector<SignalTerm> terms;
  if (!n || n.IsNull()) return Signal();
  if (n.IsSequence()) {
    for (std::size_t i = 0; i < n.size(); ++i)
      terms.push_back(parse_signal_term(n[i], source, path + "[" + std::to_string(i) + "]"));
  } else {
    terms.push_back(parse_signal_term(n, source, path));
  }
  return Signal(std::move(terms));
}

std::vector<double> parse_direction(Reader& r, const std::string& key) {
  if (!r.has(key)) return {0.0, 0.0, 0.0};
  const YAML::Node n = r.child(key);
  if (n.IsScalar()) {
    const std::string a = n.Scalar();
    if (a == "x") return {1, 0, 0};
    if (a == "y") return {0, 1, 0};
    if (a == "z") return {0, 0, 1};
  }
  std::vector<double> d = r.numbers(key, {});
  if (d.size() != 3) fail_field(r.source(), r.field(key), "must be x, y, z or a 3-vector", Reader::kind(n));
  const double norm = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  if (!(norm > 0)) fail_field(r.source(), r.field(key), "must be non-zero", "[0, 0, 0]");
  for (auto& x : d) x /= norm;
  return d;
}

void parse_rigid(const YAML::Node& n, const std::string& source, const std::string& path, RigidBodySpec& b) {
  Reader r(n, source, path);
  b.mass = r.positive("mass", b.mass);
  b.Ixx = r.positive("Ixx", b.Ixx);
  b.Iyy = r.positive("Iyy", b.Iyy);
  b.Izz = r.positive("Izz", b.Izz);
  b.Ixy = r.num("Ixy", b.Ixy);
  b.Ixz = r.num("Ixz", b.Ixz);
  b.Iyz = r.num("Iyz", b.Iyz);
  // A body's inertia tensor I (these entries, about its CM) is one only if S = ½ tr(I)·1 − I, its
  // second moment ∫ r rᵀ dm, is positive semi-definite: every principal minor of S >= 0. That holds
  // the principal moments to the triangle inequality and I itself positive definite.
  const double h = 0.5 * (b.Ixx + b.Iyy + b.Izz);
  const double S[3][3] = {{h - b.Ixx, -b.Ixy, -b.Ixz}, {-b.Ixy, h - b.Iyy, -b.Iyz}, {-b.Ixz, -b.Iyz, h - b.Izz}};
  const double tol = 1e-12 * h;
  const double d1[3] = {S[0][0], S[1][1], S[2][2]};
  const double d2[3] = {S[0][0] * S[1][1] - S[0][1] * S[0][1], S[0][0] * S[2][2] - S[0][2] * S[0][2],
                        S[1][1] * S[2][2] - S[1][2] * S[1][2]};
  const double d3 = S[0][0] * (S[1][1] * S[2][2] - S[1][2] * S[1][2]) - S[0][1] * (S[0][1] * S[2][2] - S[1][2] * S[0][2]) +
                    S[0][2] * (S[0][1] * S[1][2] - S[1][1] * S[0][2]);
  bool ok = d3 >= -tol * h * h;
  for (int i = 0; i < 3; ++i) ok = ok && d1[i] >= -tol && d2[i] >= -tol * h;
  if (!ok)
    fail_field(source, path, "is not a rigid body's inertia: the principal moments must satisfy the triangle inequality",
               "Ixx " + format_value(b.Ixx) + ", Iyy " + format_value(b.Iyy) + ", Izz " + format_value(b.Izz) + ", Ixy " +
                   format_value(b.Ixy) + ", Ixz " + format_value(b.Ixz) + ", Iyz " + format_value(b.Iyz));
}

// Reads the fields present onto `b` (the defaults, or the scenario's values for truth.overrides);
// Plausibility of what is attached to a structure, against the structure's own mass m and length L
// (docs/theory.md §10): beyond 10¹² m (m L² for a rotary inertia) or below 10⁻¹² m, the structure's
// share of the coupled mass matrix keeps fewer than 4 of double precision's 16 digits, so neither
// the truth's chain nor the identifier's elements carry it (a body 10⁶–10⁹ times heavier, which
// grounds the structure in a limiting-case study, is allowed); an offset beyond 10 L is no arm of
// this structure.
constexpr double kAttachedRatio = 1e12, kOffsetLengths = 10.0;

void check_attached_mass(const std::string& source, const std::string& field, double v, double m, bool may_be_zero) {
  if (may_be_zero && v == 0.0) return;
  if (!(v <= kAttachedRatio * m && v >= m / kAttachedRatio))
    fail_field(source, field,
               "must lie within 1e-12 and 1e12 times the structure's own mass " + format_value(m) +
                   (may_be_zero ? " (or be 0)" : "") + ": beyond, the structure's share of the mass matrix is lost to rounding",
               format_value(v));
}

void check_attached_inertia(const std::string& source, const std::string& field, double v, double m, double L) {
  if (!(v <= kAttachedRatio * m * L * L))
    fail_field(source, field,
               "must not exceed 1e12 times the structure's own m L^2 = " + format_value(m * L * L) +
                   ": beyond, the structure's share of the mass matrix is lost to rounding",
               format_value(v));
}

void check_offset(const std::string& source, const std::string& field, double v, double L) {
  if (!(std::abs(v) <= kOffsetLengths * L))
    fail_field(source, field, "must lie within 10 structure lengths (" + format_value(kOffsetLengths * L) + ") of the structure",
               format_value(v));
}

// A point element's quantities from its map (the fields present; the others keep e's values).
void parse_point_element_fields(Reader& r, PointElement& e, bool with_mass) {
  for (const auto& [key, member] : point_element_fields()) {
    if (attachment_only_field(key) && !with_mass) continue;
    e.*member = r.nonneg(key, e.*member);
  }
}

// supports: {left: {...}, right: {...}}. In truth.overrides, the fields given replace the scenario's.
void parse_supports(const YAML::Node& n, const std::string& source, const std::string& path, BeamSpec& b, bool base) {
  Reader r(n, source, path);
  for (const char* end : {"left", "right"}) {
    if (!r.has(end)) continue;
    Reader f(r.child(end), source, r.field(end));
    auto it = std::find_if(b.supports.begin(), b.supports.end(), [&](const PointElement& e) { return e.name == end; });
    if (it == b.supports.end()) {
      if (!base)
        fail_field(source, r.field(end), "overrides a support the scenario does not have (give it in beam.supports)", "'" + std::string(end) + "'");
      b.supports.push_back(PointElement{end});
      it = b.supports.end() - 1;
    }
    parse_point_element_fields(f, *it, false);
  }
}

// attachments: [{name, location, mass, inertia, k_w, k_theta, c_w, c_theta, lumped_*}]. In
// truth.overrides, each entry names an attachment of the scenario and replaces the fields it gives.
void parse_attachments(const YAML::Node& n, const std::string& source, const std::string& path, BeamSpec& b, bool base) {
  if (!n.IsSequence()) fail_field(source, path, "must be a list", Reader::kind(n));
  if (base) b.attachments.clear();
  std::set<std::string> names;
  for (std::size_t i = 0; i < n.size(); ++i) {
    const std::string item = path + "[" + std::to_string(i) + "]";
    Reader r(n[i], source, item);
    if (!r.has("name")) fail_field(source, r.field("name"), "is required (it names the attachment's parameters, attachments.NAME.mass)", "nothing");
    const std::string name = r.str("name", "");
    if (!valid_name(name) || name.find('.') != std::string::npos)
      fail_field(source, r.field("name"), "must be 1-64 characters from [A-Za-z0-9_-]", "'" + name + "'");
    if (!names.insert(name).second) fail_field(source, r.field("name"), "must be unique", "'" + name + "'");
    PointElement* e = nullptr;
    if (base) {
      b.attachments.push_back(PointElement{name});
      e = &b.attachments.back();
    } else {
      for (auto& a : b.attachments)
        if (a.name == name) e = &a;
      if (!e) fail_field(source, r.field("name"), "overrides an attachment the scenario does not have", "'" + name + "'");
    }
    if (base && !r.has("location")) fail_field(source, r.field("location"), "is required", "nothing");
    e->location = r.num("location", e->location);
    parse_point_element_fields(r, *e, true);
  }
}

// Each point element on the beam, with only what the ends leave free to act on, plausible masses
// and something to hold; the supports' stations are the ends of the length in force.
void check_point_elements(const std::string& source, const std::string& path, BeamSpec& b) {
  const double m = b.rho_A * b.length, L = b.length;
  for (auto& s : b.supports) s.location = s.name == "left" ? 0.0 : L;
  auto end_at = [&](double x) -> const EndCondition* { return x == 0.0 ? &b.left : x == L ? &b.right : nullptr; };
  auto check = [&](const std::string& f, const PointElement& e) {
    if (!(e.location >= 0.0 && e.location <= L))
      fail_field(source, f + ".location", "must lie on the beam [0, " + format_value(L) + "]", format_value(e.location));
    bool holds = false;
    for (const auto& [key, member] : point_element_fields()) holds = holds || e.*member > 0.0;
    if (!holds)
      fail_field(source, f, "holds nothing: give one of mass, inertia, k_w, k_theta, c_w, c_theta, lumped_mass with lumped_k > 0",
                 "all 0");
    // A lumped attachment is a mass on a spring: without the mass its springs are one spring in
    // series (k_w), without the spring the mass is not attached.
    if (e.has_lumped()) {
      if (!(e.lumped_mass > 0.0))
        fail_field(source, f + ".lumped_mass", "must be > 0 with lumped_k, lumped_c or lumped_k_ground (springs in series without a mass are k_w)",
                   format_value(e.lumped_mass));
      if (!(e.lumped_k > 0.0))
        fail_field(source, f + ".lumped_k", "must be > 0 with a lumped_mass (the spring that joins it to the beam)", format_value(e.lumped_k));
    }
    check_attached_mass(source, f + ".mass", e.mass, m, true);
    check_attached_mass(source, f + ".lumped_mass", e.lumped_mass, m, true);
    // A lumped mass whose own frequency lies four decades above the beam's scale √(EI/(ρA L⁴))
    // rides rigidly on w(s) (an attached mass), and a mode that far above the others is one no
    // time step of the truth or the identifier can follow.
    if (e.lumped_mass > 0.0) {
      double ei = 0.0;
      for (double v : b.EI) ei = std::max(ei, v);
      const double scale = std::sqrt(ei / (b.rho_A * L * L * L * L)), own = std::sqrt((e.lumped_k + e.lumped_k_ground) / e.lumped_mass);
      if (!(own <= 1e4 * scale))
        fail_field(source, f + ".lumped_k",
                   "with lumped_k_ground and lumped_mass gives the lumped mass a frequency of " + format_value(own) +
                       " rad/s, over 1e4 times the beam's sqrt(EI/(rho_A L^4)) = " + format_value(scale) +
                       ": it rides rigidly on the beam; give it as `mass`",
                   format_value(e.lumped_k));
    }
    check_attached_inertia(source, f + ".inertia", e.inertia, m, L);
    if (const EndCondition* ec = end_at(e.location)) {
      const std::string end = e.location == 0.0 ? "left" : "right";
      // What acts on a held degree of freedom would be a parameter no data can see.
      for (const auto& [key, member] : point_element_fields()) {
        if (!displacement_field(key)) continue;
        const double v = e.*member;
        if (*ec != EndCondition::Free && v > 0.0)
          fail_field(source, f + "." + key,
                     "acts on the " + end + " end's displacement, which the " + to_string(*ec) +
                         " end holds (an elastic end is `" + end + ": free` with its springs)",
                     format_value(v));
      }
      for (const char* key : {"inertia", "k_theta", "c_theta"}) {
        const double v =
            e.*(key == std::string("inertia") ? &PointElement::inertia : key == std::string("k_theta") ? &PointElement::k_theta : &PointElement::c_theta);
        if (*ec == EndCondition::Clamped && v > 0.0)
          fail_field(source, f + "." + key,
                     "acts on the " + end + " end's slope, which the clamped end holds (a compliant clamp is `" + end +
                         ": pinned` with supports." + end + ".k_theta)",
                     format_value(v));
      }
    }
  };
  for (const auto& s : b.supports) check(path + ".supports." + s.name, s);
  for (std::size_t i = 0; i < b.attachments.size(); ++i) check(path + ".attachments[" + std::to_string(i) + "]", b.attachments[i]);
}

// `path` is the section's dotted name in messages.
void parse_beam(const YAML::Node& n, const std::string& source, BeamSpec& b, const std::string& path = "beam") {
  Reader r(n, source, path);
  b.length = r.positive("length", b.length);
  b.left = parse_end(r, "left", b.left);
  b.right = parse_end(r, "right", b.right);
  b.rho_A = r.positive("rho_A", b.rho_A);
  b.EI = r.numbers("EI", b.EI);
  if (b.EI.empty() || b.EI.size() > 4096)
    fail_field(source, r.field("EI"), "must hold 1 to 4096 section values", std::to_string(b.EI.size()));
  for (std::size_t i = 0; i < b.EI.size(); ++i)
    if (!(b.EI[i] > 0.0))
      fail_field(source, b.EI.size() == 1 ? r.field("EI") : r.field("EI") + "[" + std::to_string(i) + "]",
                 "must be > 0", format_value(b.EI[i]));
  b.zeta = r.nonneg("zeta", b.zeta);
  if (b.zeta > 1.0) fail_field(source, r.field("zeta"), "must be at most 1: a damping ratio, and above 1 every mode is overdamped: no ringing structure this models", format_value(b.zeta));
  b.c_kv = r.nonneg("c_kv", b.c_kv);
  b.tip_mass = r.nonneg("tip_mass", b.tip_mass);
  b.tip_inertia = r.nonneg("tip_inertia", b.tip_inertia);
  check_attached_mass(source, r.field("tip_mass"), b.tip_mass, b.rho_A * b.length, true);
  check_attached_inertia(source, r.field("tip_inertia"), b.tip_inertia, b.rho_A * b.length, b.length);
  const bool base = path == "beam";
  if (r.has("supports")) parse_supports(r.child("supports"), source, r.field("supports"), b, base);
  if (r.has("attachments")) parse_attachments(r.child("attachments"), source, r.field("attachments"), b, base);
  check_point_elements(source, path, b);
  if (b.left == EndCondition::Free && b.right == EndCondition::Free) {
    // free-free is allowed (rigid modes), nothing to check here
  }
}

void parse_scole(const YAML::Node& n, const std::string& source, ScoleSpec& s, const std::string& path = "scole") {
  Reader r(n, source, path);
  const bool base = path == "scole";
  s.length = r.positive("length", s.length);
  s.rho_A = r.positive("rho_A", s.rho_A);
  if (r.has("EI")) s.EI_roll = s.EI_pitch = r.positive("EI", s.EI_roll);
  s.EI_roll = r.positive("EI_roll", s.EI_roll);
  s.EI_pitch = r.positive("EI_pitch", s.EI_pitch);
  s.GJ = r.positive("GJ", s.GJ);
  s.rho_I_psi = r.positive("rho_I_psi", s.rho_I_psi);
  s.zeta = r.nonneg("zeta", s.zeta);
  if (s.zeta > 1.0) fail_field(source, r.field("zeta"), "must be at most 1: a damping ratio, and above 1 every mode is overdamped: no ringing structure this models", format_value(s.zeta));
  s.bending_rotary_inertia = r.boolean("bending_rotary_inertia", s.bending_rotary_inertia);
  if (r.has("shuttle")) parse_rigid(r.child("shuttle"), source, r.field("shuttle"), s.shuttle);
  if (r.has("reflector")) parse_rigid(r.child("reflector"), source, r.field("reflector"), s.reflector);
  s.reflector_rx = r.num("reflector_rx", s.reflector_rx);
  s.reflector_ry = r.num("reflector_ry", s.reflector_ry);
  s.mast_root = r.numbers("mast_root", s.mast_root);
  if (s.mast_root.size() != 3)
    fail_field(source, r.field("mast_root"), "must be a 3-vector", std::to_string(s.mast_root.size()) + " values");
  // Actuators default to L/3 and 2L/3 of the length actually configured (an override keeps the
  // scenario's stations unless it names them).
  s.actuator_locations = r.numbers("actuator_locations", base ? std::vector<double>{s.length / 3.0, 2.0 * s.length / 3.0}
                                                              : s.actuator_locations);
  for (std::size_t i = 0; i < s.actuator_locations.size(); ++i) {
    const double a = s.actuator_locations[i];
    if (!(a > 0.0 && a < s.length))
      fail_field(source, r.field("actuator_locations") + "[" + std::to_string(i) + "]",
                 "must lie inside the mast (0, " + format_value(s.length) + ")", format_value(a));
  }
  s.actuator_mass = r.positive("actuator_mass", s.actuator_mass);
  s.actuator_stroke = r.positive("actuator_stroke", s.actuator_stroke);
  s.actuator_stiffness = r.nonneg("actuator_stiffness", s.actuator_stiffness);
  s.actuator_damping = r.nonneg("actuator_damping", s.actuator_damping);
  s.actuator_lag = r.nonneg("actuator_lag", s.actuator_lag);
  const double m = s.rho_A * s.length, L = s.length;
  for (const auto& [name, body] : {std::pair<const char*, const RigidBodySpec*>{"shuttle", &s.shuttle}, {"reflector", &s.reflector}}) {
    const std::string f = r.field(name);
    check_attached_mass(source, f + ".mass", body->mass, m, false);
    check_attached_inertia(source, f + ".Ixx", body->Ixx, m, L);
    check_attached_inertia(source, f + ".Iyy", body->Iyy, m, L);
    check_attached_inertia(source, f + ".Izz", body->Izz, m, L);
  }
  check_attached_mass(source, r.field("actuator_mass"), s.actuator_mass, m, false);
  check_offset(source, r.field("reflector_rx"), s.reflector_rx, L);
  check_offset(source, r.field("reflector_ry"), s.reflector_ry, L);
  for (std::size_t i = 0; i < 3; ++i) check_offset(source, r.field("mast_root") + "[" + std::to_string(i) + "]", s.mast_root[i], L);
}

// A per-storey list: one value for every storey, or one per storey.
std::vector<double> per_storey(Reader& r, const std::string& key, const std::vector<double>& dflt, std::size_t storeys,
                               const std::string& source, bool positive) {
  std::vector<double> v = r.numbers(key, dflt);
  if (v.size() == 1 && storeys > 1) v.assign(storeys, v[0]);
  if (v.size() != storeys)
    fail_field(source, r.field(key), "must hold one value, or one per storey (" + std::to_string(storeys) + ")",
               std::to_string(v.size()) + " values");
  for (std::size_t i = 0; i < v.size(); ++i)
    if (!(positive ? v[i] > 0.0 : v[i] >= 0.0) || !std::isfinite(v[i]))
      fail_field(source, r.field(key) + "[" + std::to_string(i) + "]", positive ? "must be > 0" : "must be >= 0",
                 format_value(v[i]));
  return v;
}

void parse_frame(const YAML::Node& n, const std::string& source, FrameSpec& f, const std::string& path = "frame") {
  Reader r(n, source, path);
  f.heights = r.numbers("heights", f.heights);
  if (f.heights.empty() || f.heights.size() > 64)
    fail_field(source, r.field("heights"), "must hold 1 to 64 storey heights, bottom to top", std::to_string(f.heights.size()) + " values");
  f.heights = per_storey(r, "heights", f.heights, f.heights.size(), source, true);
  const std::size_t n_storeys = f.heights.size();
  // Two columns or more hold a rigid floor from turning (docs/theory.md §2.6); one would let it
  // turn at first order, which the frame's model leaves out.
  f.columns = r.integer("columns", f.columns, 2, 16);
  f.bay = r.positive("bay", f.bay);
  f.rho_A = r.positive("rho_A", f.rho_A);
  f.EI = per_storey(r, "EI", f.EI.size() == n_storeys || f.EI.size() == 1 ? f.EI : std::vector<double>{f.EI.front()}, n_storeys,
                    source, true);
  f.floor_mass = per_storey(r, "floor_mass", f.floor_mass.size() == n_storeys || f.floor_mass.size() == 1
                                                 ? f.floor_mass : std::vector<double>{f.floor_mass.front()},
                            n_storeys, source, true);
  f.zeta = r.nonneg("zeta", f.zeta);
  if (f.zeta > 1.0) fail_field(source, r.field("zeta"), "must be at most 1: a damping ratio, and above 1 every mode is overdamped: no ringing structure this models", format_value(f.zeta));
  f.tau = r.nonneg("tau", f.tau);
  // The storeys' heights within 1e3 of each other, the floors' masses within the range a mass
  // matrix resolves against the columns'.
  const double H = f.height(), m = f.rho_A * H * f.columns;
  if (!(f.bay <= 100.0 * H && f.bay >= 1e-3 * H))
    fail_field(source, r.field("bay"), "must lie within 1e-3 and 100 times the frame's height " + format_value(H), format_value(f.bay));
  for (std::size_t i = 0; i < n_storeys; ++i) {
    if (!(f.heights[i] >= 1e-3 * H))
      fail_field(source, r.field("heights") + "[" + std::to_string(i) + "]",
                 "must be at least 1e-3 of the frame's height " + format_value(H), format_value(f.heights[i]));
    check_attached_mass(source, r.field("floor_mass") + "[" + std::to_string(i) + "]", f.floor_mass[i], m, false);
  }
}

// A sensor's or input's unit and its column's must be units of its quantity, and the unit the
// scenario's unit system gives it (no label may disagree with the numbers).
// conditioning: {offset: none | mean | {mean_before: T} | value, scale, sign, detrend} (scenario.h).
Conditioning parse_conditioning(Reader& parent, const std::string& source, bool input) {
  Conditioning c;
  if (!parent.has("conditioning")) return c;
  const YAML::Node n = parent.child("conditioning");
  const std::string path = parent.field("conditioning");
  if (!n.IsMap()) fail_field(source, path, "must be a map {offset, scale, sign, detrend}", Reader::kind(n));
  Reader r(n, source, path);
  if (r.has("offset")) {
    const YAML::Node o = r.child("offset");
    if (o.IsMap()) {
      Reader m(o, source, r.field("offset"));
      if (!m.has("mean_before")) fail_field(source, r.field("offset"), "as a map must be {mean_before: T}", Reader::kind(o));
      c.offset = Conditioning::Offset::MeanBefore;
      c.offset_value = m.num("mean_before", 0.0);
    } else if (o.IsScalar() && (o.Scalar() == "none" || o.Scalar() == "mean")) {
      c.offset = o.Scalar() == "mean" ? Conditioning::Offset::Mean : Conditioning::Offset::None;
    } else {
      c.offset = Conditioning::Offset::Value;
      c.offset_value = r.as_number(o, r.field("offset"));
    }
  }
  c.scale = r.positive("scale", 1.0);
  c.sign = r.num("sign", 1.0);
  if (c.sign != 1.0 && c.sign != -1.0) fail_field(source, r.field("sign"), "must be 1 or -1", format_value(c.sign));
  c.detrend = r.boolean("detrend", false);
  if (input && r.has("window")) {
    const YAML::Node w = r.child("window");
    if (w.IsScalar() && (w.Scalar() == "auto" || w.Scalar() == "none")) {
      c.window = w.Scalar() == "auto" ? Conditioning::Window::Auto : Conditioning::Window::None;
    } else if (w.IsSequence() && w.size() == 2) {
      c.window = Conditioning::Window::Span;
      c.window_from = r.as_number(w[0], r.field("window[0]"));
      c.window_to = r.as_number(w[1], r.field("window[1]"));
      if (!(c.window_to > c.window_from))
        fail_field(source, r.field("window"), "must be [from, to] with to > from (seconds)",
                   "[" + format_value(c.window_from) + ", " + format_value(c.window_to) + "]");
    } else {
      fail_field(source, r.field("window"), "must be auto, none or [from, to] (seconds)", Reader::kind(w));
    }
  }
  return c;
}

nlohmann::json conditioning_json(const Conditioning& c) {
  nlohmann::json j = nlohmann::json::object();
  if (c.offset == Conditioning::Offset::Mean) j["offset"] = "mean";
  else if (c.offset == Conditioning::Offset::MeanBefore) j["offset"] = {{"mean_before", c.offset_value}};
  else if (c.offset == Conditioning::Offset::Value) j["offset"] = c.offset_value;
  if (c.scale != 1.0) j["scale"] = c.scale;
  if (c.sign != 1.0) j["sign"] = c.sign;
  if (c.detrend) j["detrend"] = true;
  if (c.window == Conditioning::Window::None) j["window"] = "none";
  if (c.window == Conditioning::Window::Span) j["window"] = {c.window_from, c.window_to};
  return j;
}

void check_units(const Scenario& sc, const Reader& r, const std::string& kind, const std::string& unit,
                 const std::string& column_unit) {
  const auto q = units::quantity_of_kind(kind);
  if (!q) return;
  if (!unit.empty())
    if (const auto why = units::problem_with(unit, *q)) fail_field(sc.source, r.field("unit"), "must be a unit of " + std::string(units::quantity_name(*q)) + " (" + *why + ")", "'" + unit + "'");
  if (!column_unit.empty())
    if (const auto why = units::problem_with(column_unit, *q))
      fail_field(sc.source, r.field("column_unit"), "must be a unit of " + std::string(units::quantity_name(*q)) + " (" + *why + ")", "'" + column_unit + "'");
  if (unit.empty() || sc.units == units::System::None) return;
  const std::string want = units::system_unit(sc.units, *q);
  if (!units::conversion(unit, want, *q).identity())
    fail_field(sc.source, r.field("unit"),
               "must be the " + std::string(units::quantity_name(*q)) + " unit of the scenario's units (" +
                   units::system_name(sc.units) + ": " + want + ")",
               "'" + unit + "'");
}

void parse_inputs(const YAML::Node& n, Scenario& sc) {
  if (!n || n.IsNull()) return;
  if (!n.IsSequence()) fail_field(sc.source, "inputs", "must be a list", Reader::kind(n));
  std::set<std::string> names;
  for (std::size_t i = 0; i < n.size(); ++i) {
    const std::string path = "inputs[" + std::to_string(i) + "]";
    Reader r(n[i], sc.source, path);
    InputSpec in;
    in.name = r.str("name", "u" + std::to_string(i + 1));
    if (!names.insert(in.name).second) fail_field(sc.source, r.field("name"), "must be unique", "'" + in.name + "'");
    in.at = r.choice_of("at", sc.structure == Structure::Scole ? Site::Reflector
                              : sc.structure == Structure::Frame ? Site::Frame : Site::Beam);
    in.kind = r.choice_of("kind", InputKind::Force);
    in.location = r.num("location", 0.0);
    if (r.has("attachment")) {
      // A force on a lumped attachment's mass: at its station, on its own degree of freedom.
      in.attachment = r.str("attachment", "");
      const PointElement* e = nullptr;
      for (const auto& a : sc.beam.attachments)
        if (a.name == in.attachment) e = &a;
      if (sc.structure != Structure::Beam || !e || !(e->lumped_mass > 0.0))
        fail_field(sc.source, r.field("attachment"),
                   "must name an attachment of the beam with a lumped_mass (beam.attachments[].name)", "'" + in.attachment + "'");
      if (in.kind != InputKind::Force)
        fail_field(sc.source, r.field("kind"), "must be 'force' on a lumped attachment (it moves along w only)", quoted(in.kind));
      if (r.has("location") && in.location != e->location)
        fail_field(sc.source, r.field("location"),
                   "must be the attachment's own station (" + format_value(e->location) + ") or left out", format_value(in.location));
      in.location = e->location;
    }
    in.direction = parse_direction(r, "direction");
    in.unit = r.str("unit", "");
    in.signal_from = r.choice_of("signal_from", in.signal_from);
    in.interpolation = r.choice_of("interpolation", in.interpolation);
    in.signal = parse_signal(r.child("signal"), sc.source, r.field("signal"));
    in.column = r.str("column", "");
    in.column_unit = r.str("column_unit", "");
    check_units(sc, r, to_string(in.kind), in.unit, in.column_unit);
    in.conditioning = parse_conditioning(r, sc.source, true);
    sc.inputs.push_back(std::move(in));
  }
}

// A value v of a sensor kind's own field f for sensor s (read from `source`, at `field`), by
// the field's rule.
void check_sensor_field(const Scenario& sc, const std::string& source, const std::string& field, const SensorField& f,
                        const SensorSpec& s, double v) {
  if (f.rule == SensorField::Rule::Nonzero && !(v != 0.0))
    fail_field(source, field, "must be nonzero (" + std::string(f.why) + ")", format_value(v));
  if (f.rule == SensorField::Rule::Station) {
    check_location(sc, field, s.at, v, source);
    if (v == s.location)
      fail_field(source, field, "must differ from location (" + std::string(f.why) + ")", format_value(v));
  }
}

// The numbers the sensor's kind declares (types.h, SensorKindTraits::fields), each checked by its
// rule, and none that only another kind declares.
void parse_sensor_fields(const Scenario& sc, Reader& r, SensorSpec& s) {
  const SensorKindTraits& own = sensor_traits(s.kind);
  const std::string kind = to_string(s.kind);
  for (const SensorField& f : own.fields) {
    if (!f.name) continue;
    if (!r.has(f.name))
      fail_field(sc.source, r.field(f.name), "is required for " + std::string(own.plural) + " (" + f.meaning + ")",
                 "none");
    const double v = r.num(f.name, 0.0);
    check_sensor_field(sc, sc.source, r.field(f.name), f, s, v);
    s.fields[f.name] = v;
  }
  for (const SensorKindTraits& other : kSensorKinds)
    for (const SensorField& f : other.fields)
      if (f.name && !s.fields.count(f.name) && r.has(f.name))
        fail_field(sc.source, r.field(f.name),
                   "belongs to " + std::string(other.plural) + " (kind: " + to_string(other.kind) + ")",
                   "'" + kind + "' sensor");
}

void parse_sensors(const YAML::Node& n, Scenario& sc) {
  if (!n || n.IsNull()) return;
  if (!n.IsSequence()) fail_field(sc.source, "sensors", "must be a list", Reader::kind(n));
  std::set<std::string> names;
  for (std::size_t i = 0; i < n.size(); ++i) {
    const std::string path = "sensors[" + std::to_string(i) + "]";
    Reader r(n[i], sc.source, path);
    SensorSpec s;
    s.name = r.str("name", "y" + std::to_string(i + 1));
    if (!names.insert(s.name).second) fail_field(sc.source, r.field("name"), "must be unique", "'" + s.name + "'");
    s.at = r.choice_among("at", sc.structure == Structure::Scole ? Site::Mast
                                : sc.structure == Structure::Frame ? Site::Frame : Site::Beam,
                          {Site::Beam, Site::Mast, Site::Reflector, Site::Shuttle, Site::Frame});
    s.kind = r.choice_of("kind", SensorKind::Displacement);
    s.location = r.num("location", 0.0);
    s.direction = parse_direction(r, "direction");
    s.unit = r.str("unit", "");
    s.noise_std = r.nonneg("noise_std", 0.0);
    s.column = r.str("column", "");
    s.column_unit = r.str("column_unit", "");
    check_units(sc, r, to_string(s.kind), s.unit, s.column_unit);
    s.conditioning = parse_conditioning(r, sc.source, false);
    parse_sensor_fields(sc, r, s);
    // The identifier models an ideal sensor plus noise: a bias or drift here would be data it
    // cannot explain, so they belong to the truth's side of a mismatch study only.
    for (const char* key : {"bias", "drift"})
      if (r.has(key))
        fail_field(sc.source, r.field(key),
                   "is refused here: bias and drift describe the truth's sensor errors: set them under "
                   "truth.overrides.sensors",
                   Reader::kind(r.child(key)));
    sc.sensors.push_back(std::move(s));
  }
}

// identification.frf (scenario.h FrfSpec).
void parse_frf(Reader& parent, const std::string& source, FrfSpec& f) {
  const YAML::Node n = parent.child("frf");
  const std::string path = parent.field("frf");
  if (!n.IsMap()) fail_field(source, path, "must be a map {estimator, segment, overlap, window, lines, decay, stations, reference, relative_std, averages}", Reader::kind(n));
  Reader r(n, source, path);
  f.estimator = r.choice_of("estimator", f.estimator);
  f.segment = r.nonneg("segment", f.segment);
  f.overlap = r.nonneg("overlap", f.overlap);
  if (!(f.overlap < 1.0)) fail_field(source, r.field("overlap"), "must be in [0, 1) (a fraction of a segment)", format_value(f.overlap));
  f.window = r.choice_of("window", f.window);
  f.lines = r.numbers("lines", {});
  for (std::size_t i = 0; i < f.lines.size(); ++i)
    if (!(std::isfinite(f.lines[i]) && f.lines[i] > 0.0) || (i > 0 && !(f.lines[i] > f.lines[i - 1])))
      fail_field(source, r.field("lines") + "[" + std::to_string(i) + "]", "must be a frequency > 0 Hz above the one before", format_value(f.lines[i]));
  if (r.has("stations")) {
    const YAML::Node m = r.child("stations");
    if (!m.IsMap()) fail_field(source, r.field("stations"), "must be a map sensor: \"<node><sign><axis>\"", Reader::kind(m));
    for (const auto& kv : m) {
      const std::string key = kv.first.as<std::string>();
      if (!kv.second.IsScalar()) fail_field(source, r.field("stations") + "." + key, "must be a string such as \"12+Y\"", Reader::kind(kv.second));
      f.stations.emplace_back(key, kv.second.Scalar());
    }
  }
  if (r.has("decay")) {
    f.decay = r.nonneg("decay", 0.0);
    if (f.estimator != FrfEstimatorKind::Impact)
      fail_field(source, r.field("decay"), "is the impact estimator's exponential window (estimator: impact)", format_value(f.decay));
  }
  f.reference = r.str("reference", "");
  f.relative_std = r.nonneg("relative_std", 0.0);
  f.averages = r.integer("averages", 0, 0, 1000000);
}

void parse_identification(const YAML::Node& n, const std::string& source, IdentificationSpec& id) {
  Reader r(n, source, "identification");
  id.parameterization = r.choice("parameterization", id.parameterization, {"physical", "paper"});
  id.estimate = r.strings("estimate");
  if (r.has("initial")) {
    const YAML::Node m = r.child("initial");
    if (!m.IsMap()) fail_field(source, "identification.initial", "must be a map name: value", Reader::kind(m));
    for (const auto& kv : m) {
      const std::string key = kv.first.as<std::string>();
      const double v = r.as_number(kv.second, "identification.initial." + key);
      if (!(v > 0.0)) fail_field(source, "identification.initial." + key, "must be > 0", format_value(v));
      id.initial[key] = v;
    }
  }
  id.elements = r.integer("elements", id.elements, 1, limits::kMaxElements);
  id.sections = r.integer("sections", id.sections, 0, limits::kMaxElements);
  id.data_elements = r.integer("data_elements", id.data_elements, 0, limits::kMaxDataElements);
  id.method = r.choice_of("method", id.method);
  id.max_iterations = r.integer("max_iterations", id.max_iterations, 0, 100000);
  id.gradient_tolerance = r.positive("gradient_tolerance", id.gradient_tolerance);
  if (!(id.gradient_tolerance < 1.0))
    fail_field(source, "identification.gradient_tolerance",
               "must be below 1 (on the scaled gradient: at 1 or more the start already passes it, and \"converged\" would say nothing)",
               format_value(id.gradient_tolerance));
  id.step_tolerance = r.positive("step_tolerance", id.step_tolerance);
  if (!(id.step_tolerance < 1.0))
    fail_field(source, "identification.step_tolerance",
               "must be below 1 (a relative parameter change: at 1 or more any first step passes it)", format_value(id.step_tolerance));
  id.continuation_misfit = r.nonneg("continuation_misfit", id.continuation_misfit);
  if (r.is_scalar("band", "auto") || r.is_scalar("band", "none"))
    id.band_mode = r.str("band", "auto") == "none" ? IdentificationSpec::BandMode::None : IdentificationSpec::BandMode::Auto;
  else
    id.band = r.numbers("band", {});
  if (!id.band.empty()) {
    if (id.band.size() != 2)
      fail_field(source, "identification.band", "must be [f_lo, f_hi] in Hz (two numbers), auto or none", std::to_string(id.band.size()) + " numbers");
    if (!(std::isfinite(id.band[0]) && id.band[0] >= 0.0))
      fail_field(source, "identification.band[0]", "must be a frequency >= 0 Hz (0: low-pass only)", format_value(id.band[0]));
    if (!(std::isfinite(id.band[1]) && id.band[1] > id.band[0]))
      fail_field(source, "identification.band[1]", "must be a finite frequency above band[0] = " + format_value(id.band[0]) + " Hz",
                 format_value(id.band[1]));
  }
  id.steepest_weights = r.numbers("steepest_weights", {});
  for (std::size_t i = 0; i < id.steepest_weights.size(); ++i)
    if (!(id.steepest_weights[i] > 0))
      fail_field(source, "identification.steepest_weights[" + std::to_string(i) + "]", "must be > 0",
                 format_value(id.steepest_weights[i]));
  id.integrator = r.choice_of("integrator", id.integrator);
  id.time_step = r.nonneg("time_step", id.time_step);
  id.step_rule = r.choice_of("step_rule", id.step_rule);
  id.rtol = r.positive("rtol", id.rtol);
  // "auto" (what identify.json's settings echo for the default) or a fraction.
  if (r.has("model_error"))
    id.model_error = r.is_scalar("model_error", "auto") ? -1.0 : r.nonneg("model_error", 0.0);
  if (id.model_error > 1.0)
    fail_field(source, "identification.model_error",
               "must be at most 1 (a fraction of each sensor's RMS signal: above 1 the fit test accepts a model that explains "
               "nothing)",
               format_value(id.model_error));
  id.restarts = r.integer("restarts", id.restarts, 0, 10);
  id.start = r.choice_of("start", id.start);
  id.model = r.choice_of("model", id.model);
  id.initial_state = r.choice_of("initial_state", id.initial_state);
  id.initial_state_modes = r.integer("initial_state_modes", id.initial_state_modes, 0, kMaxInitialStateModes);
  if (id.initial_state == InitialState::Estimate && !id.band.empty())
    fail_field(source, "identification.band",
               "cannot be stated with initial_state: estimate (the filter's commutation with the model needs a record that "
               "starts at rest; give band: none)",
               "[" + format_value(id.band[0]) + ", " + format_value(id.band[1]) + "]");
  if (id.initial_state == InitialState::Estimate && id.model == Model::Nonlinear)
    fail_field(source, "identification.initial_state", "needs the linear model", "estimate");
  id.domain = r.choice_of("domain", id.domain);
  if (r.has("frf")) parse_frf(r, source, id.frf);
  if (id.domain == Domain::Frequency) {
    if (id.model == Model::Nonlinear) fail_field(source, "identification.domain", "needs the linear model (a frequency response is a linear model's)", "frequency");
    if (id.initial_state == InitialState::Estimate)
      fail_field(source, "identification.initial_state",
                 "is a time record's unknown; frequency responses of a steady state have none (give rest, or domain: time)", "estimate");
  }
  if (!id.band.empty() && id.model == Model::Nonlinear)
    fail_field(source, "identification.band", "needs the linear model (a filter commutes with a linear time-invariant model only)",
               "model: nonlinear");
  if (r.has("smoothness")) {
    const YAML::Node m = r.child("smoothness");
    if (m.IsScalar() && m.Scalar() == "discrepancy")
      id.smoothness = -1.0;
    else
      id.smoothness = r.nonneg("smoothness", 0.0);
  }
  if (r.has("uncertain")) {
    // Paths are checked against the whole scenario once it is read (parse_scenario).
    const YAML::Node m = r.child("uncertain");
    if (!m.IsMap()) fail_field(source, "identification.uncertain", "must be a map field: tolerance", Reader::kind(m));
    for (const auto& kv : m) {
      UncertainSpec u;
      u.field = kv.first.as<std::string>();
      const std::string field = "identification.uncertain." + u.field;
      const std::string text = kv.second.IsScalar() ? kv.second.Scalar() : "";
      if (text == "true" || text == "false") {
        u.is_switch = true;
        u.alternative = text == "true";
      } else {
        u.tolerance = r.as_number(kv.second, field);
        if (!(u.tolerance > 0.0) || !std::isfinite(u.tolerance)) fail_field(source, field, "must be a tolerance > 0", format_value(u.tolerance));
      }
      id.uncertain.push_back(u);
    }
  }
}

void parse_truth(const YAML::Node& n, const std::string& source, Scenario& sc) {
  TruthModelSpec& t = sc.truth;
  Reader r(n, source, "truth");
  t.segments = r.integer("segments", t.segments, 2, limits::kMaxSegments);
  t.integrator = r.str("integrator", t.integrator);
  t.accuracy = r.positive("accuracy", t.accuracy);
  if (!(t.accuracy < 1)) fail_field(source, "truth.accuracy", "must be < 1", format_value(t.accuracy));
  t.output_interval = r.nonneg("output_interval", t.output_interval);
  t.anti_alias_hz = r.nonneg("anti_alias_hz", t.anti_alias_hz);
  t.large_motion = r.boolean("large_motion", t.large_motion);
  if (r.has("overrides")) {
    // Kept as text and applied on demand (truth_scenario), onto whatever the structure section
    // holds then; applied once here so that its errors surface while parsing.
    YAML::Emitter e;
    e << r.child("overrides");
    t.overrides = e.c_str();
    t.overrides_source = source;
    truth_scenario(sc);
  }
}

// truth.overrides.sensors: a list of partial sensor entries, each naming a sensor of the scenario,
// applied onto t.sensors (the truth's). location and direction are read as in the main section
// (a direction is normalised, so a misaligned sensor is written as the vector it measures along);
// bias and drift are the truth's sensor errors (SensorSpec).
void parse_sensor_overrides(const YAML::Node& n, const std::string& source, Scenario& t) {
  if (!n.IsSequence()) fail_field(source, "truth.overrides.sensors", "must be a list", Reader::kind(n));
  std::set<std::string> names;
  for (std::size_t i = 0; i < n.size(); ++i) {
    const std::string path = "truth.overrides.sensors[" + std::to_string(i) + "]";
    Reader r(n[i], source, path);
    if (!r.has("name")) fail_field(source, r.field("name"), "must name a sensor of the scenario", "none");
    const std::string name = r.str("name", "");
    auto it = std::find_if(t.sensors.begin(), t.sensors.end(), [&](const SensorSpec& x) { return x.name == name; });
    if (it == t.sensors.end()) {
      std::string list;
      for (const auto& x : t.sensors) list += (list.empty() ? "" : ", ") + x.name;
      fail_field(source, r.field("name"), "must name a sensor of the scenario (" + (list.empty() ? "none" : list) + ")",
                 "'" + name + "'");
    }
    if (!names.insert(name).second) fail_field(source, r.field("name"), "must be unique", "'" + name + "'");
    SensorSpec& se = *it;
    if (r.has("location")) {
      if (!has_station(se.at))
        fail_field(source, r.field("location"),
                   "applies to beam and mast sensors only (sensor '" + name + "' is at " + to_string(se.at) + ")",
                   format_value(r.num("location", 0.0)));
      se.location = r.num("location", se.location);
      check_location(t, r.field("location"), se.at, se.location, source);
    }
    if (r.has("direction")) {
      if (t.structure != Structure::Scole)
        fail_field(source, r.field("direction"), "does not apply to a " + std::string(to_string(t.structure)) + " sensor (it measures w or w_s)",
                   Reader::kind(r.child("direction")));
      se.direction = parse_direction(r, "direction");
    }
    // The kind's own fields (a strain gauge's offset, a relative gauge's reference), by their rules.
    for (const SensorField& f : sensor_traits(se.kind).fields) {
      if (!f.name || !(r.has(f.name) || r.has("location"))) continue;
      const double v = r.has(f.name) ? r.num(f.name, 0.0) : se.field(f.name);
      check_sensor_field(t, source, r.field(r.has(f.name) ? f.name : "location"), f, se, v);
      se.fields[f.name] = v;
    }
    se.bias = r.num("bias", se.bias);
    se.drift = r.num("drift", se.drift);
  }
}

}  // namespace

ScenarioFieldRecorder::ScenarioFieldRecorder() : outer_(recorded_fields) { recorded_fields = &fields_; }
ScenarioFieldRecorder::~ScenarioFieldRecorder() { recorded_fields = outer_; }

Scenario parse_scenario(const std::string& yaml_text, const std::string& source) {
  check_utf8(yaml_text, source);
  check_yaml_nesting(yaml_text, source);
  YAML::Node root;
  try {
    // (An empty document, as after a trailing `---`, is no second scenario.)
    std::vector<YAML::Node> docs;
    for (const auto& d : YAML::LoadAll(yaml_text))
      if (d && !d.IsNull()) docs.push_back(d);
    if (docs.size() > 1)
      throw InputError(source + ": holds " + std::to_string(docs.size()) + " YAML documents; a scenario is one");
    if (!docs.empty()) root = docs.front();
  } catch (const YAML::Exception& e) {
    throw InputError(source + ": malformed YAML at line " + std::to_string(e.mark.line + 1) +
                     ", column " + std::to_string(e.mark.column + 1) + ": " + e.msg);
  }
  if (!root || root.IsNull()) throw InputError(source + ": empty scenario document");
  Scenario sc;
  sc.source = source;
  try {
    check_yaml_document(root, source);  // repeated keys, UTF-8, keys without values (input_file.h)
    Reader r(root, source, "");
    sc.name = r.str("name", "unnamed");
    sc.description = r.str("description", "");
    sc.structure = r.choice_of("structure", Structure::Beam);
    if (r.has("units")) {
      const std::string u = r.str("units", "");
      const auto system = units::parse_system(u);
      if (!system) fail_field(source, "units", "must be SI or slug-ft-s", "'" + u + "'");
      sc.units = *system;
    }
    // The section of the other structure would be read and then ignored: refused instead.
    if (r.has("beam") && sc.structure != Structure::Beam)
      fail_field(source, "beam", "describes a beam, but the scenario's structure is " + std::string(to_string(sc.structure)) +
                                     " (remove the section, or set structure: beam)", "a beam section");
    if (r.has("scole") && sc.structure != Structure::Scole)
      fail_field(source, "scole", "describes SCOLE, but the scenario's structure is " + std::string(to_string(sc.structure)) +
                                      " (remove the section, or set structure: scole)", "a scole section");
    if (r.has("frame") && sc.structure != Structure::Frame)
      fail_field(source, "frame", "describes a frame, but the scenario's structure is " + std::string(to_string(sc.structure)) +
                                      " (remove the section, or set structure: frame)", "a frame section");
    if (r.has("beam")) parse_beam(r.child("beam"), source, sc.beam);
    if (r.has("frame")) parse_frame(r.child("frame"), source, sc.frame);
    if (r.has("scole")) parse_scole(r.child("scole"), source, sc.scole);
    {
      Reader s(r.child("simulation"), source, "simulation");
      sc.simulation.duration = s.positive("duration", sc.simulation.duration);
      sc.simulation.sample_interval = s.positive("sample_interval", sc.simulation.sample_interval);
      sc.simulation.seed = static_cast<unsigned>(s.integer("seed", 1, 0, 2147483647));
      sc.simulation.record_start = s.nonneg("record_start", 0.0);
      if (!(sc.simulation.record_start + 2.0 * sc.simulation.sample_interval <= sc.simulation.duration))
        fail_field(source, "simulation.record_start",
                   "must leave at least two sample intervals before simulation.duration (" +
                       format_value(sc.simulation.duration) + ")",
                   format_value(sc.simulation.record_start));
      if (sc.simulation.sample_interval > sc.simulation.duration)
        fail_field(source, "simulation.sample_interval", "must not exceed simulation.duration (" +
                                                             format_value(sc.simulation.duration) + ")",
                   format_value(sc.simulation.sample_interval));
    }
    parse_inputs(r.child("inputs"), sc);
    parse_sensors(r.child("sensors"), sc);
    if (r.has("data")) {
      Reader d(r.child("data"), source, "data");
      sc.data.time_column = d.str("time_column", "");
      sc.data.time_unit = d.str("time_unit", "");
      if (d.has("sample_rate")) sc.data.sample_rate = d.positive("sample_rate", 0.0);  // (absent: not stated)
      sc.data.window = d.numbers("window", {});
      if (!sc.data.window.empty()) {
        if (sc.data.window.size() != 2)
          fail_field(source, "data.window", "must be [t_start, t_end] in s (two numbers)", std::to_string(sc.data.window.size()) + " numbers");
        if (!(std::isfinite(sc.data.window[0]) && sc.data.window[0] >= 0.0))
          fail_field(source, "data.window[0]", "must be a time >= 0 s", format_value(sc.data.window[0]));
        if (!(std::isfinite(sc.data.window[1]) && sc.data.window[1] > sc.data.window[0]))
          fail_field(source, "data.window[1]", "must be a finite time after data.window[0] = " + format_value(sc.data.window[0]) + " s",
                     format_value(sc.data.window[1]));
      }
      if (!sc.data.time_unit.empty())
        if (const auto why = units::problem_with(sc.data.time_unit, units::Quantity::Time))
          fail_field(source, "data.time_unit", "must be a unit of time (" + *why + ")", "'" + sc.data.time_unit + "'");
    }
    if (r.has("identification")) parse_identification(r.child("identification"), source, sc.identification);
    if (r.has("truth")) parse_truth(r.child("truth"), source, sc);
  } catch (const YAML::Exception& e) {
    throw InputError(source + ": malformed YAML at line " + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
  validate_scenario(sc);
  return sc;
}

Scenario truth_scenario(const Scenario& s) {
  Scenario t = s;
  if (s.truth.overrides.empty()) return t;
  const std::string& source = s.truth.overrides_source.empty() ? s.source : s.truth.overrides_source;
  try {
    Reader o(YAML::Load(s.truth.overrides), source, "truth.overrides");
    if (o.has("beam")) {
      if (s.structure != Structure::Beam) fail_field(source, "truth.overrides.beam", "must match the structure", "'" + std::string(to_string(s.structure)) + "'");
      parse_beam(o.child("beam"), source, t.beam, "truth.overrides.beam");
    }
    if (o.has("frame")) {
      if (s.structure != Structure::Frame) fail_field(source, "truth.overrides.frame", "must match the structure", "'" + std::string(to_string(s.structure)) + "'");
      parse_frame(o.child("frame"), source, t.frame, "truth.overrides.frame");
      if (t.frame.storeys() != s.frame.storeys())
        fail_field(source, "truth.overrides.frame.heights", "must keep the scenario's " + std::to_string(s.frame.storeys()) + " storeys",
                   std::to_string(t.frame.storeys()) + " values");
    }
    if (o.has("scole")) {
      if (s.structure != Structure::Scole) fail_field(source, "truth.overrides.scole", "must match the structure", "'" + std::string(to_string(s.structure)) + "'");
      parse_scole(o.child("scole"), source, t.scole, "truth.overrides.scole");
    }
    // After the structure: a location is checked against the length the truth simulates.
    if (o.has("sensors")) parse_sensor_overrides(o.child("sensors"), source, t);
  } catch (const YAML::Exception& e) {
    throw InputError(source + ": truth.overrides: malformed YAML: " + e.msg);
  }
  return t;
}

bool has_truth_overrides(const Scenario& s) { return to_json(s)["truth"].contains("overrides"); }

Scenario load_scenario(const std::string& name_or_file) {
  const std::string builtin = builtin_scenario_yaml(name_or_file);
  if (!builtin.empty()) return parse_scenario(builtin, "built-in scenario '" + name_or_file + "'");
  std::error_code ec;
  if (!std::filesystem::exists(name_or_file, ec)) {
    const bool looks_like_file = name_or_file.find('/') != std::string::npos ||
                                 name_or_file.find(".yaml") != std::string::npos ||
                                 name_or_file.find(".yml") != std::string::npos;
    if (looks_like_file) throw InputError("scenario file '" + name_or_file + "': cannot be opened");
    std::string names;
    for (const auto& n : builtin_scenario_names()) names += (names.empty() ? "" : ", ") + n;
    throw InputError("scenario '" + name_or_file + "': not a built-in scenario (" + names +
                     ") nor a readable file");
  }
  return parse_scenario(read_text_file(name_or_file, "scenario file"), "scenario '" + name_or_file + "'");
}

namespace {

// A signal's terms as the scenario writes them.
nlohmann::json signal_json(const Signal& sig) {
  using nlohmann::json;
  json terms = json::array();
  for (const auto& t : sig.terms()) {
    json j{{"type", to_string(t.type)}, {"amplitude", t.amplitude}, {"t0", t.t0}};
    if (t.width > 0) j["width"] = t.width;
    if (t.type == SignalTerm::Type::Sine) {
      j["frequency"] = t.f0;
      j["phase"] = t.phase;
      j["duration"] = t.duration;
    }
    if (t.type == SignalTerm::Type::Multisine) {
      j.erase("width");
      j["period"] = t.width;
      j["f0"] = t.f0;
      j["f1"] = t.f1;
      j["duration"] = t.duration;
    }
    if (t.type == SignalTerm::Type::Chirp) {
      j["f0"] = t.f0;
      j["f1"] = t.f1;
      j["duration"] = t.duration;
    }
    if (t.type == SignalTerm::Type::Table || t.type == SignalTerm::Type::CubicTable) {
      j["times"] = t.times;
      j["values"] = t.values;
    }
    terms.push_back(j);
  }
  return terms;
}

}  // namespace

nlohmann::json to_json(const Scenario& s) {
  using nlohmann::json;
  auto rigid = [](const RigidBodySpec& b) {
    return json{{"mass", b.mass}, {"Ixx", b.Ixx}, {"Iyy", b.Iyy}, {"Izz", b.Izz},
                {"Ixy", b.Ixy}, {"Ixz", b.Ixz}, {"Iyz", b.Iyz}};
  };
  json j;
  j["name"] = s.name;
  j["description"] = s.description;
  j["source"] = s.source;
  j["structure"] = to_string(s.structure);
  if (s.units != units::System::None) j["units"] = units::system_name(s.units);
  if (!s.data.time_column.empty() || !s.data.time_unit.empty() || s.data.sample_rate > 0 || !s.data.window.empty()) {
    j["data"] = {{"time_column", s.data.time_column}, {"time_unit", s.data.time_unit}};
    if (s.data.sample_rate > 0) j["data"]["sample_rate"] = s.data.sample_rate;
    if (!s.data.window.empty()) j["data"]["window"] = s.data.window;
  }
  auto beam = [](const BeamSpec& b) {
    json j{{"length", b.length}, {"left", to_string(b.left)}, {"right", to_string(b.right)},
                {"rho_A", b.rho_A}, {"EI", b.EI}, {"zeta", b.zeta}, {"c_kv", b.c_kv},
                {"tip_mass", b.tip_mass}, {"tip_inertia", b.tip_inertia}};
    auto fields = [](const PointElement& e, bool with_mass) {
      json f = json::object();
      for (const auto& [key, member] : point_element_fields())
        if (with_mass || !attachment_only_field(key)) f[key] = e.*member;
      return f;
    };
    if (!b.supports.empty()) {
      json s = json::object();
      for (const auto& e : b.supports) s[e.name] = fields(e, false);
      j["supports"] = s;
    }
    if (!b.attachments.empty()) {
      json a = json::array();
      for (const auto& e : b.attachments) {
        json f = fields(e, true);
        f["name"] = e.name;
        f["location"] = e.location;
        a.push_back(f);
      }
      j["attachments"] = a;
    }
    return j;
  };
  auto scole = [&](const ScoleSpec& c) {
    return json{{"length", c.length}, {"rho_A", c.rho_A}, {"EI_roll", c.EI_roll}, {"EI_pitch", c.EI_pitch},
                {"GJ", c.GJ}, {"rho_I_psi", c.rho_I_psi}, {"zeta", c.zeta},
                {"bending_rotary_inertia", c.bending_rotary_inertia}, {"shuttle", rigid(c.shuttle)},
                {"reflector", rigid(c.reflector)}, {"reflector_rx", c.reflector_rx},
                {"reflector_ry", c.reflector_ry}, {"mast_root", c.mast_root},
                {"actuator_locations", c.actuator_locations}, {"actuator_mass", c.actuator_mass},
                {"actuator_stroke", c.actuator_stroke}, {"actuator_stiffness", c.actuator_stiffness},
                {"actuator_damping", c.actuator_damping}, {"actuator_lag", c.actuator_lag}};
  };
  // The structure section, and the truth's overrides as the fields whose values differ from it.
  json structure, truth_structure;
  const Scenario ts = truth_scenario(s);
  if (s.structure == Structure::Beam) {
    structure = beam(s.beam);
    truth_structure = beam(ts.beam);
  } else if (s.structure == Structure::Frame) {
    const auto frame = [](const FrameSpec& f) {
      return json{{"heights", f.heights}, {"columns", f.columns}, {"bay", f.bay}, {"rho_A", f.rho_A},
                  {"EI", f.EI},           {"floor_mass", f.floor_mass}, {"zeta", f.zeta}, {"tau", f.tau}};
    };
    structure = frame(s.frame);
    truth_structure = frame(ts.frame);
  } else {
    structure = scole(s.scole);
    truth_structure = scole(ts.scole);
  }
  j[to_string(s.structure)] = structure;
  json overrides = json::object();
  for (const auto& [k, v] : truth_structure.items()) {
    if (v == structure[k]) continue;
    if (v.is_object()) {
      json sub = json::object();
      for (const auto& [k2, v2] : v.items())
        if (v2 != structure[k][k2]) sub[k2] = v2;
      overrides[k] = sub;
    } else {
      overrides[k] = v;
    }
  }
  j["inputs"] = json::array();
  for (const auto& in : s.inputs) {
    j["inputs"].push_back({{"name", in.name},
                           {"at", to_string(in.at)},
                           {"kind", to_string(in.kind)},
                           {"location", in.location},
                           {"direction", in.direction},
                           {"unit", in.unit},
                           {"signal_from", to_string(in.signal_from)},
                           {"interpolation", to_string(in.interpolation)},
                           {"signal", signal_json(in.signal)}});
    if (!in.attachment.empty()) j["inputs"].back()["attachment"] = in.attachment;
    if (!in.column.empty()) j["inputs"].back()["column"] = in.column;
    if (!in.column_unit.empty()) j["inputs"].back()["column_unit"] = in.column_unit;
    if (in.conditioning.stated()) j["inputs"].back()["conditioning"] = conditioning_json(in.conditioning);
  }
  j["sensors"] = json::array();
  for (const auto& se : s.sensors) {
    j["sensors"].push_back({{"name", se.name}, {"at", to_string(se.at)}, {"kind", to_string(se.kind)}, {"location", se.location},
                            {"direction", se.direction}, {"unit", se.unit}, {"noise_std", se.noise_std}});
    for (const auto& [name, value] : se.fields) j["sensors"].back()[name] = value;
    if (!se.column.empty()) j["sensors"].back()["column"] = se.column;
    if (!se.column_unit.empty()) j["sensors"].back()["column_unit"] = se.column_unit;
    if (se.conditioning.stated()) j["sensors"].back()["conditioning"] = conditioning_json(se.conditioning);
  }
  j["simulation"] = {{"duration", s.simulation.duration}, {"sample_interval", s.simulation.sample_interval},
                     {"record_start", s.simulation.record_start},
                     {"seed", s.simulation.seed}};
  const auto& id = s.identification;
  j["identification"] = {{"parameterization", id.parameterization}, {"estimate", id.estimate},
                         {"initial", id.initial}, {"elements", id.elements}, {"sections", id.sections}, {"data_elements", id.data_elements},
                         {"method", to_string(id.method)}, {"max_iterations", id.max_iterations},
                         {"gradient_tolerance", id.gradient_tolerance}, {"step_tolerance", id.step_tolerance},
                         {"continuation_misfit", id.continuation_misfit},
                         {"band", !id.band.empty() ? json(id.band) : json(id.band_mode == IdentificationSpec::BandMode::None ? "none" : "auto")},
                         {"steepest_weights", id.steepest_weights}, {"integrator", to_string(id.integrator)},
                         {"time_step", id.time_step}, {"step_rule", to_string(id.step_rule)}, {"rtol", id.rtol},
                         {"model_error", id.model_error < 0 ? json("auto") : json(id.model_error)},
                         {"restarts", id.restarts}, {"start", to_string(id.start)}, {"model", to_string(id.model)},
                         {"smoothness", id.smoothness < 0 ? json("discrepancy") : json(id.smoothness)},
                         {"initial_state", to_string(id.initial_state)}, {"initial_state_modes", id.initial_state_modes},
                         {"domain", to_string(id.domain)}};
  if (id.domain == Domain::Frequency) {
    json f = {{"estimator", to_string(id.frf.estimator)}, {"segment", id.frf.segment}, {"overlap", id.frf.overlap},
              {"window", to_string(id.frf.window)}, {"lines", id.frf.lines}};
    if (id.frf.decay >= 0) f["decay"] = id.frf.decay;
    if (!id.frf.stations.empty()) {
      json st = json::object();
      for (const auto& [sensor, station] : id.frf.stations) st[sensor] = station;
      f["stations"] = st;
    }
    if (!id.frf.reference.empty()) f["reference"] = id.frf.reference;
    if (id.frf.relative_std > 0) f["relative_std"] = id.frf.relative_std;
    if (id.frf.averages > 0) f["averages"] = id.frf.averages;
    j["identification"]["frf"] = f;
  }
  if (!id.uncertain.empty()) {
    json u = json::object();
    for (const auto& x : id.uncertain) u[x.field] = x.is_switch ? json(x.alternative) : json(x.tolerance);
    j["identification"]["uncertain"] = u;
  }
  j["truth"] = {{"segments", s.truth.segments}, {"integrator", s.truth.integrator},
                {"accuracy", s.truth.accuracy}, {"output_interval", s.truth.output_interval},
                {"anti_alias_hz", s.truth.anti_alias_hz}, {"large_motion", s.truth.large_motion}};
  // Sensor overrides: per sensor, its name and the fields in which the truth's sensor differs.
  json sensor_overrides = json::array();
  auto sensor_fields = [](const SensorSpec& se) {
    json f{{"location", se.location}, {"direction", se.direction}, {"bias", se.bias}, {"drift", se.drift}};
    for (const auto& [name, value] : se.fields) f[name] = value;
    return f;
  };
  for (std::size_t i = 0; i < s.sensors.size() && i < ts.sensors.size(); ++i) {
    const json base = sensor_fields(s.sensors[i]), truth = sensor_fields(ts.sensors[i]);
    json diff{{"name", s.sensors[i].name}};
    for (const auto& [k, v] : truth.items())
      if (v != base[k]) diff[k] = v;
    if (diff.size() > 1) sensor_overrides.push_back(diff);
  }
  json truth_overrides = json::object();
  if (!overrides.empty()) truth_overrides[to_string(s.structure)] = overrides;
  if (!sensor_overrides.empty()) truth_overrides["sensors"] = sensor_overrides;
  if (!truth_overrides.empty()) j["truth"]["overrides"] = truth_overrides;
  return j;
}

}  // namespace scoleid::io
