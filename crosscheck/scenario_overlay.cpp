#include "scoleid/crosscheck/scenario_overlay.h"

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "scoleid/io/error.h"
#include "scoleid/io/validation.h"

namespace scoleid::crosscheck {

namespace fs = std::filesystem;

namespace {

// Maps merge key by key; anything else replaces.
YAML::Node merge(const YAML::Node& base, const YAML::Node& over) {
  if (!over || over.IsNull()) return YAML::Clone(base);
  if (!base || !base.IsMap() || !over.IsMap()) return YAML::Clone(over);
  YAML::Node out = YAML::Clone(base);
  for (const auto& kv : over) {
    const std::string key = kv.first.as<std::string>();
    out[key] = merge(base[key], kv.second);
  }
  return out;
}

std::string text_of(const YAML::Node& n) {
  YAML::Emitter e;
  e << n;
  return e.c_str();
}

}  // namespace

std::string overlaid_scenario_yaml(const std::string& base, const std::string& study_file, const std::string& field,
                                   const std::vector<std::string>& overlays) {
  std::string text = io::builtin_scenario_yaml(base), source = "built-in scenario '" + base + "'";
  if (text.empty()) {
    const fs::path p = fs::path(study_file).parent_path() / base;
    std::ifstream in(p);
    if (base.empty() || !fs::is_regular_file(p) || !in)
      io::fail_field(study_file, field, "is neither a built-in scenario nor a readable file beside the study file", "'" + base + "'");
    std::stringstream ss;
    ss << in.rdbuf();
    text = ss.str();
    source = p.string();
  }
  try {
    YAML::Node node = YAML::Load(text);
    for (const auto& o : overlays)
      if (!o.empty()) node = merge(node, YAML::Load(o));
    return text_of(node);
  } catch (const YAML::Exception& e) {
    throw io::InputError("'" + study_file + "': scenario '" + source + "': malformed YAML: " + e.msg);
  }
}

io::Scenario checked_scenario(const std::string& yaml, const std::string& source) {
  io::Scenario sc = io::parse_scenario(yaml, source);
  io::validate_scenario(sc);
  return sc;
}

std::string path_overlay(const std::string& dotted_path, const std::string& value_yaml) {
  YAML::Node value = YAML::Load(value_yaml);
  std::vector<std::string> keys;
  std::string k;
  for (char c : dotted_path) {
    if (c == '.') {
      keys.push_back(k);
      k.clear();
    } else {
      k += c;
    }
  }
  keys.push_back(k);
  for (auto it = keys.rbegin(); it != keys.rend(); ++it) {
    YAML::Node m(YAML::NodeType::Map);
    m[*it] = value;
    value = m;
  }
  return text_of(value);
}

}  // namespace scoleid::crosscheck
