#pragma once
// The tests' data files (tests/data): scenarios the tests start from, exported lab files.
#include <gtest/gtest.h>

#include <functional>
#include <stdexcept>
#include <string>

#include "common/cli_support.h"
#include "scoleid/io/error.h"
#include "scoleid/io/scenario.h"

namespace scoleid::test {

// tests/data/<relative>.
inline std::string test_data_path(const std::string& relative) { return std::string(SCOLEID_TEST_DATA_DIR) + "/" + relative; }

// The YAML text of tests/data/scenarios/<name>.yaml (name: "<test file>/<scenario>").
inline std::string test_scenario(const std::string& name) {
  const std::string text = slurp(test_data_path("scenarios/" + name + ".yaml"));
  if (text.empty()) throw std::runtime_error("no test scenario " + name);
  return text;
}

// `text` with its first `from` replaced by `to`; a test failure if `from` is not there.
inline std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// The message of the InputError that `f` throws; "" if it throws none.
inline std::string input_error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const io::InputError& e) {
    return e.what();
  }
  return "";
}

// The message of the InputError that parsing scenario `yaml` (named `source`) throws; "" if it parses.
inline std::string scenario_error(const std::string& yaml, const std::string& source) {
  try {
    io::parse_scenario(yaml, source);
  } catch (const io::InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace scoleid::test
