#pragma once
// A fixture for tests that run scole-truth from the shell: a scratch directory per test (named
// after the suite, the process and the test), files written into it, and a run's exit code and
// standard error.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "common/cli_support.h"

namespace scoleid::model::test {

struct CliResult {
  int code = -1;
  std::string err;
};

class TruthCliFixture : public ::testing::Test {
protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = std::filesystem::temp_directory_path() / ("scoleid_" + std::string(info->test_suite_name()) + "_" +
                                                     std::to_string(::getpid()) + "_" + info->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::string write(const std::string& name, const std::string& text) { return scoleid::test::write_file(dir_ / name, text); }
  // scole-truth with `args` (stdout discarded).
  CliResult run(const std::string& args) {
    const std::filesystem::path err = dir_ / "stderr.txt";
    const std::string cmd = std::string(SCOLE_TRUTH_EXE) + " " + args + " 2> " + err.string() + " > /dev/null";
    CliResult r;
    r.code = scoleid::test::sh(cmd);
    r.err = scoleid::test::slurp(err);
    return r;
  }

  std::filesystem::path dir_;
};

}  // namespace scoleid::model::test
