#pragma once
// Registry of built-in scenarios. Each is YAML text parsed by the same parser as a user's file,
// so the built-ins exercise the schema exactly as files do.
#include <string>
#include <vector>

namespace scoleid::io {

struct BuiltinScenario {
  std::string name;
  std::string description;
  std::string yaml;
};

std::vector<BuiltinScenario> beam_builtin_scenarios();   // builtin_beam.cpp
std::vector<BuiltinScenario> scole_builtin_scenarios();  // builtin_scole.cpp

}  // namespace scoleid::io
