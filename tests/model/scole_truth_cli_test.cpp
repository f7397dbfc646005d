// The scole-truth executable's contract (DESIGN §6): exit codes, one-line errors naming the
// file, the field and the value, no partial output; and on success truth.csv / truth.json with
// the scenario's columns, sampled 0..T inclusive, holding the beam's physical response.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "scoleid/io/data_files.h"

namespace fs = std::filesystem;

namespace {

struct CliResult {
  int code = -1;
  std::string err;
};

class ScoleTruthCli : public ::testing::Test {
protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("scole_truth_cli_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string write(const std::string& name, const std::string& text) {
    const fs::path p = dir_ / name;
    std::ofstream(p) << text;
    return p.string();
  }
  CliResult run(const std::string& args) {
    const fs::path err = dir_ / "stderr.txt";
    const std::string cmd = std::string(SCOLE_TRUTH_EXE) + " " + args + " 2> " + err.string() + " > /dev/null";
    const int status = std::system(cmd.c_str());
    CliResult r;
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    std::ifstream in(err);
    std::stringstream ss;
    ss << in.rdbuf();
    r.err = ss.str();
    return r;
  }
  static int lines(const std::string& s) { return static_cast<int>(std::count(s.begin(), s.end(), '\n')); }

  fs::path dir_;
};

const char* kBeam = R"(name: cli-beam
structure: beam
beam: {length: 10, left: pinned, right: pinned, rho_A: 67, EI: 23000, zeta: 0}
inputs:
  - {name: P, at: beam, kind: force, location: 5, unit: N, signal: {type: step, amplitude: 10, t0: 0}}
sensors:
  - {name: w_mid, at: beam, kind: displacement, location: 5, unit: m}
simulation: {duration: 4, sample_interval: 0.01, seed: 1}
truth: {segments: 20, integrator: rk-merson, accuracy: 1e-6}
)";

}  // namespace

TEST_F(ScoleTruthCli, BadFieldValueExits2WithOneLineAndNoOutput) {
  std::string yaml = kBeam;
  yaml.replace(yaml.find("rho_A: 67"), 9, "rho_A: -3");
  const std::string file = write("bad.yaml", yaml);
  const fs::path out = dir_ / "out";
  const CliResult r = run("--scenario " + file + " --out " + out.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find(file), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("beam.rho_A"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("-3"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out / "truth.csv"));
  EXPECT_FALSE(fs::exists(out / "truth.json"));
}

TEST_F(ScoleTruthCli, InputTheStructureCannotTakeExits2) {
  std::string yaml = kBeam;
  yaml.replace(yaml.find("at: beam, kind: force"), 8, "at: shuttle");
  const std::string file = write("bad.yaml", yaml);
  const fs::path out = dir_ / "out";
  const CliResult r = run("--scenario " + file + " --out " + out.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("inputs[0].at"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("shuttle"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out / "truth.csv"));
}

TEST_F(ScoleTruthCli, UnknownIntegratorAndUnknownScenarioExit2) {
  std::string yaml = kBeam;
  yaml.replace(yaml.find("integrator: rk-merson"), 21, "integrator: leapfrog");
  const std::string file = write("bad.yaml", yaml);
  CliResult r = run("--scenario " + file + " --out " + (dir_ / "out").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("truth.integrator"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("leapfrog"), std::string::npos) << r.err;
  r = run("--scenario no-such-scenario --out " + (dir_ / "out").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(lines(r.err), 1) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "out" / "truth.csv"));
  r = run("--no-such-option");
  EXPECT_EQ(r.code, 2);
}

TEST_F(ScoleTruthCli, BuiltinsAreListed) {
  const fs::path list = dir_ / "list.txt";
  const int status = std::system((std::string(SCOLE_TRUTH_EXE) + " --list-scenarios > " + list.string()).c_str());
  ASSERT_EQ(WEXITSTATUS(status), 0);
  std::ifstream in(list);
  std::stringstream ss;
  ss << in.rdbuf();
  for (const char* n : {"paper-beam-1", "paper-beam-2", "paper-beam-3", "beam-ei8", "paper-scole-1",
                        "paper-scole-2", "scole-slew"})
    EXPECT_NE(ss.str().find(n), std::string::npos) << n;
}

// A step load P at midspan of a simply supported beam: the undamped response oscillates about
// the static deflection P L^3 / (48 EI) and peaks at twice it (dynamic amplification of a
// suddenly applied load; the first mode carries 98.6 % of the static midspan deflection).
TEST_F(ScoleTruthCli, StepLoadPeaksAtTwiceTheStaticDeflection) {
  const std::string file = write("beam.yaml", kBeam);
  const fs::path out = dir_ / "out";
  const CliResult r = run("--scenario " + file + " --out " + out.string() + " --quiet");
  ASSERT_EQ(r.code, 0) << r.err;
  const scoleid::io::DataTable tab = scoleid::io::read_csv((out / "truth.csv").string());
  ASSERT_EQ(tab.names, (std::vector<std::string>{"P", "w_mid"}));
  ASSERT_EQ(tab.t.size(), 401u);
  EXPECT_DOUBLE_EQ(tab.t.front(), 0.0);
  EXPECT_NEAR(tab.t.back(), 4.0, 1e-12);
  for (double p : tab.columns[0]) EXPECT_EQ(p, 10.0);
  const double w_static = 10.0 * 1000.0 / (48.0 * 23000.0);
  const double peak = *std::max_element(tab.columns[1].begin(), tab.columns[1].end());
  EXPECT_NEAR(peak / (2 * w_static), 1.0, 0.03);
  EXPECT_GE(*std::min_element(tab.columns[1].begin(), tab.columns[1].end()), -0.03 * w_static);

  const auto meta = scoleid::io::read_truth_meta((out / "truth.json").string());
  ASSERT_EQ(meta.columns.size(), 2u);
  EXPECT_EQ(meta.columns[0].kind, "input");
  EXPECT_EQ(meta.columns[0].quantity, "force");
  EXPECT_EQ(meta.columns[1].kind, "output");
  EXPECT_EQ(meta.columns[1].quantity, "displacement");
  EXPECT_EQ(meta.columns[1].location, 5.0);
  EXPECT_EQ(meta.true_parameters.at("EI"), 23000.0);
  EXPECT_EQ(meta.true_parameters.at("rho_A"), 67.0);
  EXPECT_EQ(meta.true_parameters.at("zeta"), 0.0);
}
