// The scole-truth executable's contract (docs/theory.md §10): exit codes, one-line errors naming the
// file, the field and the value, no partial output; and on success truth.csv / truth.json with
// the scenario's columns, sampled 0..T inclusive, holding the beam's physical response.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "scoleid/io/data_files.h"

#include "cli_fixture.h"
#include "common/test_data.h"

namespace fs = std::filesystem;

namespace {

using scoleid::model::test::CliResult;

class ScoleTruthCli : public scoleid::model::test::TruthCliFixture {
protected:
  static int lines(const std::string& s) { return static_cast<int>(std::count(s.begin(), s.end(), '\n')); }
  // Runs the truth on scenario text `yaml` (written to bad.yaml) into out/: exit 2 and one line on
  // stderr holding the file's path and each of `needles`; no truth.csv or truth.json written.
  void expect_refused(const std::string& yaml, std::initializer_list<std::string> needles) {
    const std::string file = write("bad.yaml", yaml);
    const fs::path out = dir_ / "out";
    const CliResult r = run("--scenario " + file + " --out " + out.string());
    EXPECT_EQ(r.code, 2);
    EXPECT_EQ(lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(file), std::string::npos) << r.err;
    for (const auto& n : needles) EXPECT_NE(r.err.find(n), std::string::npos) << n << ": " << r.err;
    EXPECT_FALSE(fs::exists(out / "truth.csv"));
    EXPECT_FALSE(fs::exists(out / "truth.json"));
  }
};

const std::string kBeam = scoleid::test::test_scenario("scole_truth_cli_test/cli-beam");

}  // namespace

TEST_F(ScoleTruthCli, BadFieldValueExits2WithOneLineAndNoOutput) {
  expect_refused(scoleid::test::replaced(kBeam, "rho_A: 67", "rho_A: -3"), {"beam.rho_A", "-3"});
}

TEST_F(ScoleTruthCli, EulerBernoulliMastIsRefusedByTheChain) {
  // Rigid segments always carry the section's bending rotary inertia (docs/theory.md §3.3).
  expect_refused(scoleid::test::test_scenario("scole_truth_cli_test/cli-eb"), {"scole.bending_rotary_inertia", "false"});
  EXPECT_FALSE(fs::exists(dir_ / "out"));
}

TEST_F(ScoleTruthCli, InputTheStructureCannotTakeExits2) {
  expect_refused(scoleid::test::replaced(kBeam, "at: beam", "at: shuttle"), {"inputs[0].at", "shuttle"});
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
  EXPECT_EQ(meta.true_parameters.at("c_kv"), 0.0);
}

// ------------------------------------------------------------------------------- hardening

namespace {
std::string with(const std::string& from, const std::string& to) { return scoleid::test::replaced(kBeam, from, to); }
}  // namespace

TEST_F(ScoleTruthCli, CommandLineOverridesPassTheScenarioChecks) {
  const std::string file = write("s.yaml", kBeam);
  const fs::path out = dir_ / "out";
  for (const char* opt_c : {"--segments 10000000", "--segments 1", "--accuracy nan", "--accuracy 2", "--accuracy 1e-30"}) {
    const std::string opt = opt_c;
    const CliResult r = run("--scenario " + file + " --out " + out.string() + " " + opt);
    EXPECT_EQ(r.code, 2) << opt << ": " << r.err;
    EXPECT_EQ(lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(opt.substr(0, opt.find(' '))), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out));
  }
}

TEST_F(ScoleTruthCli, CountsAndMagnitudesAreBoundedBeforeAnyWork) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {with("duration: 4", "duration: 1e9"), "simulation.sample_interval"},
      {with("sample_interval: 0.01", "sample_interval: 1e-9"), "simulation.sample_interval"},
      {with("EI: 23000", "EI: 1e300"), "beam.EI"},
      {with("amplitude: 10", "amplitude: 1e308"), "inputs[0].signal.amplitude"},
      {with("segments: 20", "segments: 10000000"), "truth.segments"}};
  for (const auto& [yaml, field] : cases) {
    const std::string file = write("s.yaml", yaml);
    const auto t0 = std::chrono::steady_clock::now();
    const CliResult r = run("--scenario " + file + " --out " + (dir_ / "out").string());
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 5.0) << field;
    EXPECT_EQ(r.code, 2) << field << ": " << r.err;
    EXPECT_EQ(lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(field), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "out"));
  }
}

TEST_F(ScoleTruthCli, NamesThatWouldBreakTheCsvAreRefused) {
  for (const std::string& name : {std::string("'w,tip'"), std::string("\"w\\ntip\""), std::string("''"), std::string("P")}) {
    const std::string file = write("s.yaml", with("name: w_mid", "name: " + name));
    const CliResult r = run("--scenario " + file + " --out " + (dir_ / "out").string());
    EXPECT_EQ(r.code, 2) << name << ": " << r.err;
    EXPECT_EQ(lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find("sensors[0].name"), std::string::npos) << r.err;
  }
}

TEST_F(ScoleTruthCli, SigtermMidRunLeavesNoOutputAndExits143) {
  const fs::path out = dir_ / "out";
  const pid_t pid = ::fork();
  if (pid == 0) {
    std::FILE* devnull = std::fopen("/dev/null", "w");
    if (devnull) {
      ::dup2(fileno(devnull), 1);
      ::dup2(fileno(devnull), 2);
    }
    ::execl(SCOLE_TRUTH_EXE, SCOLE_TRUTH_EXE, "--scenario", "paper-scole-1", "--segments", "160", "--out", out.c_str(), "--quiet",
            static_cast<char*>(nullptr));
    ::_exit(98);
  }
  ::usleep(800000);  // a 160-segment SCOLE truth takes about ten seconds; the signal lands mid-run
  ::kill(pid, SIGTERM);
  int status = 0;
  ::waitpid(pid, &status, 0);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 143) << status;
  EXPECT_FALSE(fs::exists(out));
  for (const auto& e : fs::directory_iterator(dir_)) ADD_FAILURE() << "left behind: " << e.path();
}

TEST_F(ScoleTruthCli, TruthCsvAndJsonAreReplacedTogether) {
  const std::string file = write("s.yaml", with("duration: 4", "duration: 0.5"));
  const fs::path out = dir_ / "out";
  ASSERT_EQ(run("--scenario " + file + " --out " + out.string()).code, 0);
  const auto first = scoleid::io::read_csv((out / "truth.csv").string());
  // A second run that fails leaves both files of the first; a later good run replaces both.
  const std::string bad = write("bad.yaml", with("rho_A: 67", "rho_A: -1"));
  ASSERT_EQ(run("--scenario " + bad + " --out " + out.string()).code, 2);
  EXPECT_EQ(scoleid::io::read_csv((out / "truth.csv").string()).t.size(), first.t.size());
  const std::string longer = write("long.yaml", with("duration: 4", "duration: 1"));
  ASSERT_EQ(run("--scenario " + longer + " --out " + out.string()).code, 0);
  EXPECT_GT(scoleid::io::read_csv((out / "truth.csv").string()).t.size(), first.t.size());
  EXPECT_NE(scoleid::io::read_truth_meta((out / "truth.json").string()).settings.dump().find("\"duration\":1.0"),
            std::string::npos);
}
