#pragma once
// Registry of built-in scenarios: the YAML files of io/scenarios/, compiled in as text. Each is
// parsed by the same parser as a user's file, so the built-ins exercise the schema exactly as
// files do. A file's first line, a comment, is the one-line summary --list-scenarios prints.
#include <string>
#include <vector>

namespace scoleid::io {

struct BuiltinScenarioText {
  std::string name;  // the file's stem
  std::string yaml;  // the file, as written
};

// In the order --list-scenarios shows them (builtin_scenarios.cpp, written by CMake).
const std::vector<BuiltinScenarioText>& builtin_scenario_texts();

}  // namespace scoleid::io
