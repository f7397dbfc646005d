#include "scoleid/io/builtin.h"

#include <cstdio>

#include "scoleid/io/error.h"
#include "scoleid/io/scenario.h"

namespace scoleid::io {

namespace {
std::vector<BuiltinScenario> all_builtins() {
  auto all = beam_builtin_scenarios();
  for (auto& s : scole_builtin_scenarios()) all.push_back(std::move(s));
  return all;
}
}  // namespace

std::vector<std::string> builtin_scenario_names() {
  std::vector<std::string> names;
  for (const auto& s : all_builtins()) names.push_back(s.name);
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
  throw InputError("--print-scenario: '" + name + "' is not a built-in scenario (" + names + ")");
}

std::string builtin_scenario_yaml(const std::string& name) {
  for (const auto& s : all_builtins())
    if (s.name == name) return s.yaml;
  return {};
}

std::string builtin_scenario_description(const std::string& name) {
  for (const auto& s : all_builtins())
    if (s.name == name) return s.description;
  return {};
}

}  // namespace scoleid::io
