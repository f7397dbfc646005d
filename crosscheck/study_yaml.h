#pragma once
// Reading the study files (mismatch families, campaigns): one io::InputError line naming the file,
// the field and the value. Internal to crosscheck/ (yaml-cpp stays out of the public headers).
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <string>

#include "scoleid/io/error.h"
#include "scoleid/io/number.h"

namespace scoleid::crosscheck::study {

[[noreturn]] inline void bad(const std::string& file, const std::string& field, const std::string& what, const std::string& value) {
  io::fail_field(file, field, what, value);
  throw io::InputError(file);  // not reached
}

// A node as one line of YAML (flow style): for messages, and overlays kept as text.
inline std::string text_of(const YAML::Node& n) {
  YAML::Emitter e;
  e << YAML::Flow << n;
  return e.c_str();
}

inline double number_of(const YAML::Node& n, const std::string& file, const std::string& field) {
  double v = std::nan("");
  if (!n.IsScalar() || !io::parse_decimal(n.Scalar(), v))
    bad(file, field, "must be a decimal number", n.IsScalar() ? "'" + n.Scalar() + "'" : text_of(n));
  if (!std::isfinite(v)) bad(file, field, "must be finite", n.Scalar());
  return v;
}

}  // namespace scoleid::crosscheck::study
