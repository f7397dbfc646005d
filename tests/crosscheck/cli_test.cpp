// The scole-crosscheck program: bad input is one line and exit 2 with nothing written; `all` on a
// beam writes every table, its CSV and JSON, report.md, and its identification recovers the
// truth's parameters from FE data to the FE's accuracy; each verb replaces only its own files.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "test_support.h"

namespace fs = std::filesystem;

namespace {
using scoleid::test::sh;
using scoleid::test::slurp;
fs::path scratch(const std::string& tag) { return scoleid::test::scratch("xc-cli", tag); }
const std::string exe = SCOLE_CROSSCHECK_EXE;
}  // namespace

TEST(CrosscheckCli, BadInputIsOneLineExitTwoNothingWritten) {
  const fs::path d = scratch("bad");
  EXPECT_EQ(sh(exe + " modes --scenario no-such-scenario --out " + (d / "out").string() + " 2> " + (d / "err").string()), 2);
  const std::string err = slurp(d / "err");
  EXPECT_NE(err.find("no-such-scenario"), std::string::npos) << err;
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  EXPECT_FALSE(fs::exists(d / "out"));
  EXPECT_EQ(sh(exe + " modes --scenario paper-beam-1 --levels 9 --out " + (d / "out").string() + " 2> /dev/null"), 2);
  EXPECT_EQ(sh(exe + " report --scenario paper-beam-1 --out " + (d / "out").string() + " 2> /dev/null"), 2);
  EXPECT_FALSE(fs::exists(d / "out"));
  EXPECT_EQ(sh(exe + " frobnicate 2> /dev/null"), 2);
  // A chain of one segment is no chain (it crashed the modes verb); an FE step that makes a
  // record of 10^10 steps is refused before any truth is run.
  for (const std::string verb : {"modes", "trajectories", "identify"}) {
    EXPECT_EQ(sh(exe + " " + verb + " --scenario paper-beam-1 --segments 1 --out " + (d / "out").string() + " 2> " +
                 (d / "err").string()),
              2)
        << verb;
    EXPECT_NE(slurp(d / "err").find("segments must be in [2,"), std::string::npos) << slurp(d / "err");
  }
  EXPECT_EQ(sh(exe + " trajectories --scenario paper-beam-1 --segments 4 --levels 2 --fe-step 1e-9 --out " +
               (d / "out").string() + " 2> " + (d / "err").string()),
            2);
  EXPECT_NE(slurp(d / "err").find("--fe-step 1e-09 gives"), std::string::npos) << slurp(d / "err");
  EXPECT_FALSE(fs::exists(d / "out"));
  // A step longer than the sample interval (0.01 s), here longer than the 10 s record: refused before
  // any truth is run.
  EXPECT_EQ(sh(exe + " trajectories --scenario paper-beam-1 --segments 4 --levels 2 --fe-step 100 --out " +
               (d / "out").string() + " 2> " + (d / "err").string()),
            2);
  EXPECT_NE(slurp(d / "err").find("--fe-step 100 exceeds the record's sample interval 0.01"), std::string::npos)
      << slurp(d / "err");
  EXPECT_FALSE(fs::exists(d / "out"));
  // `report` on a modes.json that is not what `modes` writes: exit 2, the user's file and the field
  // named (not the staging copy), the file left as it was.
  fs::create_directories(d / "rep");
  { std::ofstream(d / "rep" / "modes.json") << "[1, 2, 3]\n"; }
  EXPECT_EQ(sh(exe + " report --scenario paper-beam-1 --out " + (d / "rep").string() + " 2> " + (d / "err").string()), 2);
  const std::string rep_err = slurp(d / "err");
  EXPECT_NE(rep_err.find((d / "rep" / "modes.json").string() + ": field '(top level)'"), std::string::npos) << rep_err;
  EXPECT_EQ(rep_err.find("staging"), std::string::npos) << rep_err;
  EXPECT_EQ(std::count(rep_err.begin(), rep_err.end(), '\n'), 1) << rep_err;
  EXPECT_EQ(slurp(d / "rep" / "modes.json"), "[1, 2, 3]\n");
  // `modes ... | head -c 1`: the reader goes away; the verb still commits its outputs and exits 0.
  std::signal(SIGPIPE, SIG_DFL);
  EXPECT_EQ(sh("bash -c '" + exe + " modes --scenario paper-beam-1 --levels 1 --count 3 --out " + (d / "piped").string() +
               " 2> /dev/null | head -c 1 > /dev/null; exit ${PIPESTATUS[0]}'"),
            0);
  EXPECT_TRUE(fs::exists(d / "piped" / "modes.json"));
  for (const auto& e : fs::directory_iterator(d))
    EXPECT_EQ(e.path().filename().string().find("staging"), std::string::npos) << e.path() << " left behind";
  // `suite --collect` before the families have run: exit 2, one line, nothing created.
  fs::create_directories(d / "empty");
  EXPECT_EQ(sh(exe + " suite --collect --out " + (d / "empty").string() + " 2> " + (d / "err").string()), 2);
  const std::string collect_err = slurp(d / "err");
  EXPECT_EQ(std::count(collect_err.begin(), collect_err.end(), '\n'), 1) << collect_err;
  EXPECT_FALSE(fs::exists(d / "empty" / "results"));
  fs::remove_all(d);
}

TEST(CrosscheckCli, AllWritesTablesReportAndRecoversFromFeData) {
  const fs::path d = scratch("all");
  const fs::path out = d / "xc";
  ASSERT_EQ(sh(exe + " all --scenario paper-beam-2 --quiet --out " + out.string() + " > " + (d / "stdout").string()), 0);
  for (const char* f : {"modes.csv", "mac.csv", "modes.json", "trajectories.csv", "trajectories.json", "overlay.csv",
                        "identify.csv", "identify.json", "report.md", "modes_convergence.csv", "identify_convergence.csv"})
    EXPECT_TRUE(fs::exists(out / f)) << f;
  EXPECT_TRUE(fs::exists(out / "truths" / "n40" / "truth.csv"));
  const std::string summary = slurp(d / "stdout");
  for (const char* w : {"modes", "trajectories", "parameters", "uncertainty"}) EXPECT_NE(summary.find(w), std::string::npos) << summary;
  const std::string md = slurp(out / "report.md");
  EXPECT_NE(md.find("## Natural frequencies"), std::string::npos);
  EXPECT_NE(md.find("## Identification"), std::string::npos);

  std::ifstream in(out / "identify.json");
  const auto j = nlohmann::json::parse(in);
  EXPECT_TRUE(j["all_converged"].get<bool>());
  for (const auto& p : j["parameters"]) {
    // FE-on-FE: the identifier recovers its own model's parameters (measured <= 3.4e-5).
    EXPECT_LT(std::abs(p["fe_on_fe_relative_error"].get<double>()), 1e-3) << p["name"];
    // On the Simbody truth the error is reported for every level, and it is a number.
    EXPECT_EQ(p["relative_error"].size(), 3u);
  }

  // A later verb replaces only its own files: modes.json survives a `report`, which rewrites
  // report.md from the same JSON.
  const auto modes_time = fs::last_write_time(out / "modes.json");
  ASSERT_EQ(sh(exe + " report --scenario paper-beam-2 --quiet --out " + out.string() + " > /dev/null"), 0);
  EXPECT_EQ(fs::last_write_time(out / "modes.json"), modes_time);
  EXPECT_TRUE(fs::exists(out / "identify.json"));
  EXPECT_EQ(slurp(out / "report.md"), md);
  fs::remove_all(d);
}

namespace {
void write(const fs::path& p, const std::string& text) {
  std::ofstream(p) << text;
}
}  // namespace

// scole-crosscheck suite: a family file with an error is one line naming the file, the field and
// the value, exit 2, and nothing is run or written.
TEST(CrosscheckSuite, BadFamilyFileIsOneLineExitTwoNothingWritten) {
  const fs::path d = scratch("suite-bad");
  const std::string good_head =
      "family: f\nmismatch: m\nreason: r\nscenario: paper-beam-1\n";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {good_head + "cases: [{label: a, size: 1}]\nfrobnicate: 1\n", "frobnicate"},
      {good_head + "cases: []\n", "cases"},
      {good_head + "cases: [{label: 'a b', size: 1}]\n", "cases[0].label"},
      {good_head + "cases: [{label: a, size: .nan}]\n", "cases[0].size"},
      {good_head + "cases: [{label: a, size: 1, overlay: {beam: {EI: -5}}}]\n", "EI"},
      {"family: f\nmismatch: m\nreason: r\nscenario: no-such-base\ncases: [{label: a, size: 1}]\n", "no-such-base"},
      {good_head + "cases: [{label: a, size: 1}]\nnoise: {relative: 2, seeds: 5}\n", "noise.relative"},
      {good_head + "cases: [{label: a, size: 1}]\nexpect: {rate: [3, 1]}\n", "expect.rate"},
      {good_head + "cases: [{label: a, size: 1, overlay: {identification: {uncertain: {beam.nothing: 1}}}}]\n", "beam.nothing"},
      {good_head + "cases: [{label: a, size: 1}\n", "malformed"},
      {good_head + "cases: [{label: a, size: 1}]\nexpect: {all_covered: 1}\n", "expect.all_covered"},
      {"family: f\nmismatch: m\nreason: r\nscenario: paper-scole-1\n"
       "cases: [{label: a, size: 1, overlay: {scole: {actuator_lag: 0.1}}}]\n", "scole.actuator_lag"},
  };
  int k = 0;
  for (const auto& [text, needle] : cases) {
    const fs::path f = d / ("bad" + std::to_string(k++) + ".yaml");
    write(f, text);
    const fs::path out = d / "out";
    EXPECT_EQ(sh(exe + " suite --only " + f.string() + " --out " + out.string() + " 2> " + (d / "err").string()), 2) << text;
    const std::string err = slurp(d / "err");
    EXPECT_NE(err.find(needle), std::string::npos) << err;
    EXPECT_NE(err.find(f.filename().string()), std::string::npos) << err;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
    EXPECT_FALSE(fs::exists(out)) << text;
  }
  EXPECT_EQ(sh(exe + " suite --only no-such-family --out " + (d / "out").string() + " 2> /dev/null"), 2);
  // The same family twice, and a seed count that has no scatter.
  write(d / "one.yaml", good_head + "cases: [{label: a, size: 1}]\n");
  write(d / "two.yaml", good_head + "cases: [{label: b, size: 2}]\n");
  EXPECT_EQ(sh(exe + " suite --only " + (d / "one.yaml").string() + " " + (d / "two.yaml").string() + " --out " +
               (d / "out").string() + " 2> /dev/null"),
            2);
  EXPECT_EQ(sh(exe + " suite --seeds 1 --only " + (d / "one.yaml").string() + " --out " + (d / "out").string() + " 2> /dev/null"), 2);
  EXPECT_FALSE(fs::exists(d / "out"));
  // An --out holding a file of the user's: refused, the file untouched, nothing added.
  fs::create_directories(d / "mine");
  write(d / "mine" / "notes.txt", "mine\n");
  EXPECT_EQ(sh(exe + " suite --only " + (d / "one.yaml").string() + " --out " + (d / "mine").string() + " 2> " +
               (d / "err").string()),
            2);
  EXPECT_NE(slurp(d / "err").find("notes.txt"), std::string::npos) << slurp(d / "err");
  EXPECT_EQ(std::distance(fs::directory_iterator(d / "mine"), fs::directory_iterator{}), 1);
  // SIGTERM while the family runs: exit 143 and nothing of it left (its truths were being written).
  const int code = sh("( " + exe + " suite --only " + (d / "one.yaml").string() + " --out " + (d / "out").string() +
                      " -q 2> /dev/null & p=$!; sleep 0.5; kill -TERM $p; wait $p )");
  EXPECT_EQ(code, 143);
  EXPECT_FALSE(fs::exists(d / "out"));
  fs::remove_all(d);
}

// A small family on a beam (the paper's Case I, chain of 10, 20 and 40 segments): the family's
// results and the suite's report; the estimate of q2 self-converges at second order, its Richardson
// limit is nearer the truth than the finest case, and the report states the coverage it measured. --collect without the family's results is an incomplete suite: refused (exit 2).
TEST(CrosscheckSuite, ChainFamilyOnABeamRunsAndReportsCoverage) {
  const fs::path d = scratch("suite-beam");
  fs::create_directories(d / "families");
  write(d / "families" / "chain.yaml",
        "family: beam-chain\nmismatch: chain of n segments\nsize_unit: n\nreason: second-order lumping\n"
        "scenario: paper-beam-1\n"
        "cases:\n  - {label: n10, size: 10, overlay: {truth: {segments: 10}}}\n"
        "  - {label: n20, size: 20, overlay: {truth: {segments: 20}}}\n"
        "  - {label: n40, size: 40, overlay: {truth: {segments: 40}}}\n"
        "expect: {rate: {q2: [1.5, 2.5]}}\n");
  const fs::path out = d / "out";
  const std::string dir = " --suite-dir " + (d / "families").string() + " --out " + out.string();
  EXPECT_EQ(sh(exe + " suite --collect -q" + dir + " > /dev/null 2>&1"), 2);
  ASSERT_EQ(sh(exe + " suite --only beam-chain -q" + dir), 0);
  const auto r = nlohmann::json::parse(slurp(out / "results" / "beam-chain.json"));
  ASSERT_EQ(r["cases"].size(), 3u);
  // q2 (1/rho_A) carries the chain's lumping; q1 sits on the geometric nonlinearity's floor.
  EXPECT_EQ(r["order_kind"], "self-convergence");
  ASSERT_EQ(r["observed_orders"]["q2"].size(), 1u);
  for (const auto& order : r["observed_orders"]["q2"]) {
    EXPECT_GT(order.get<double>(), 1.5);
    EXPECT_LT(order.get<double>(), 2.5);
  }
  const double finest = r["cases"][2]["parameters"][1]["relative_error"].get<double>();
  ASSERT_EQ(r["cases"][2]["parameters"][1]["name"], "q2");
  std::printf("q2: error %.3e at n = 40, Richardson limit %.3e, order %.2f\n", finest,
              r["richardson_limit_error"]["q2"].get<double>(), r["observed_orders"]["q2"][0].get<double>());
  EXPECT_LT(std::abs(r["richardson_limit_error"]["q2"].get<double>()), 0.25 * std::abs(finest));
  EXPECT_TRUE(r["expectations_met"].get<bool>());
  // Every estimate carries its interval and whether it covers the truth.
  int covered = 0, n = 0;
  for (const auto& c : r["cases"])
    for (const auto& q : c["parameters"]) {
      ASSERT_TRUE(q["relative_half_width"].is_number());
      const bool cov = std::abs(q["relative_error"].get<double>()) <= q["relative_half_width"].get<double>();
      EXPECT_EQ(cov, q["covered"].get<bool>());
      covered += cov;
      ++n;
    }
  sh(exe + " suite --collect" + dir + " > " + (d / "stdout").string() + " 2>&1");
  const std::string md = slurp(out / "report.md");
  const auto s = nlohmann::json::parse(slurp(out / "suite.json"));
  EXPECT_EQ(s["cases"].get<int>(), n);
  EXPECT_EQ(s["covered"].get<int>(), covered);
  EXPECT_NE(md.find("Coverage"), std::string::npos);
  EXPECT_NE(md.find("| beam-chain |"), std::string::npos);
  EXPECT_TRUE(fs::exists(out / "suite.csv"));
  EXPECT_TRUE(fs::exists(out / "suite.gp"));
  fs::remove_all(d);
}

// End to end (docs/theory.md §6.6): `modes` writes the Simbody chain's modes as modal-data.csv, and
// scole-identify --experiments fits the mast's EI and ρA to them alone, within the chain's lumping
// level (a frequency known to δ relative fixes a stiffness-to-mass ratio to about 2δ).
TEST(CrosscheckCli, ChainModesFileIdentifiesTheMastThroughScoleIdentify) {
  const fs::path d = scratch("modal");
  const std::string src = std::string(SCOLEID_SOURCE_DIR) + "/identify/examples/modal/";
  ASSERT_EQ(sh(exe + " modes --scenario " + src + "scole-modal.yaml --count 6 --quiet --out " + (d / "xc").string() + " > /dev/null"), 0);
  ASSERT_TRUE(fs::exists(d / "xc" / "modal-data.csv"));
  fs::create_directories(d / "in");
  for (const char* f : {"scole-modal.yaml", "modes-only.yaml"}) fs::copy_file(src + f, d / "in" / f);
  fs::copy_file(d / "xc" / "modal-data.csv", d / "in" / "modal-data.csv");
  ASSERT_EQ(sh(std::string(SCOLE_IDENTIFY_EXE) + " --experiments " + (d / "in" / "modes-only.yaml").string() + " -q --out " +
               (d / "id").string() + " > /dev/null 2>&1"),
            0);
  std::ifstream in(d / "id" / "identify.json");
  const auto j = nlohmann::json::parse(in);
  EXPECT_TRUE(j["converged"].get<bool>());
  // The largest relative frequency std in the file: the chain's lumping level.
  double worst = 0;
  {
    std::ifstream m(d / "in" / "modal-data.csv");
    std::string line;
    std::getline(m, line);
    while (std::getline(m, line)) {
      std::stringstream ss(line);
      std::string label, f, sd;
      std::getline(ss, label, ',');
      std::getline(ss, f, ',');
      std::getline(ss, sd, ',');
      worst = std::max(worst, std::stod(sd) / std::stod(f));
    }
  }
  const double EI = j["estimate"]["EI"].get<double>(), rho_A = j["estimate"]["rho_A"].get<double>();
  std::printf("chain modes -> EI %.4e (%.2e), rho_A %.5g (%.2e); lumping level %.2e\n", EI, EI / 4.0e7 - 1, rho_A,
              rho_A / 0.0956 - 1, worst);
  EXPECT_LT(std::abs(EI / 4.0e7 - 1.0), 2.0 * worst);  // the scenario's (default) mast: EI 4e7, rho_A 0.0956
  EXPECT_LT(std::abs(rho_A / 0.0956 - 1.0), 2.0 * worst);
  fs::remove_all(d);
}
