#pragma once
// Study files (mismatch families, campaigns) describe their runs as a base scenario plus overlays:
// YAML maps merged key by key onto it (anything that is not a map replaces). This is that merge.
#include <string>
#include <vector>

#include "scoleid/io/scenario.h"

namespace scoleid::crosscheck {

// The YAML text of `base` (a built-in scenario name, or a file path relative to the directory of
// `study_file`) with `overlays` (YAML map texts; empty ones skipped) merged on in order.
// io::InputError naming `study_file` and `field` when the base cannot be found or a text is
// malformed.
std::string overlaid_scenario_yaml(const std::string& base, const std::string& study_file, const std::string& field,
                                   const std::vector<std::string>& overlays);

// Parses and validates a scenario text; `source` names it in messages.
io::Scenario checked_scenario(const std::string& yaml, const std::string& source);

// The YAML map text {a: {b: {c: value}}} that sets the dotted path "a.b.c" to `value` (YAML text
// of a scalar, list or map).
std::string path_overlay(const std::string& dotted_path, const std::string& value_yaml);

}  // namespace scoleid::crosscheck
