#pragma once
// The tests' data files (tests/data): scenarios the tests start from, exported lab files.
#include <stdexcept>
#include <string>

#include "common/cli_support.h"

namespace scoleid::test {

// tests/data/<relative>.
inline std::string test_data_path(const std::string& relative) { return std::string(SCOLEID_TEST_DATA_DIR) + "/" + relative; }

// The YAML text of tests/data/scenarios/<name>.yaml (name: "<test file>/<scenario>").
inline std::string test_scenario(const std::string& name) {
  const std::string text = slurp(test_data_path("scenarios/" + name + ".yaml"));
  if (text.empty()) throw std::runtime_error("no test scenario " + name);
  return text;
}

}  // namespace scoleid::test
