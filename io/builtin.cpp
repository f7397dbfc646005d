#include "scoleid/io/builtin.h"

#include <cstdio>

#include "scoleid/io/error.h"
#include "scoleid/io/scenario.h"
#include "scoleid/io/validation.h"

namespace scoleid::io {

std::vector<std::string> builtin_scenario_names() {
  std::vector<std::string> names;
  for (const auto& s : builtin_scenario_texts()) names.push_back(s.name);
  return names;
}

std::string builtin_scenario_listing() {
  std::string out;
  for (const auto& n : builtin_scenario_names()) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%-16s ", n.c_str());
    out += buf + builtin_scenario_description(n) + "\n";
  }
  return out;
}

std::string builtin_scenario_text(const std::string& name) {
  const std::string yaml = builtin_scenario_yaml(name);
  if (!yaml.empty()) return yaml;
  std::string names;
  for (const auto& n : builtin_scenario_names()) names += (names.empty() ? "" : ", ") + n;
  throw InputError("'" + shorten(name) + "' is not a built-in scenario (" + names + ")");
}

std::string builtin_scenario_yaml(const std::string& name) {
  for (const auto& s : builtin_scenario_texts())
    if (s.name == name) return s.yaml;
  return {};
}

// The file's first line without its "# ".
std::string builtin_scenario_description(const std::string& name) {
  const std::string yaml = builtin_scenario_yaml(name);
  if (yaml.rfind("# ", 0) != 0) return {};
  return yaml.substr(2, yaml.find('\n') - 2);
}

}  // namespace scoleid::io
