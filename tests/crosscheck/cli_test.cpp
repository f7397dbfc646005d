// The scole-crosscheck program: bad input is one line and exit 2 with nothing written; `all` on a
// beam writes every table, its CSV and JSON, report.md, and its identification recovers the
// truth's parameters from FE data to the FE's accuracy; each verb replaces only its own files.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

namespace fs = std::filesystem;

namespace {
int sh(const std::string& cmd) {
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}
std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}
fs::path scratch(const std::string& tag) {
  const fs::path d = fs::temp_directory_path() / ("scoleid-xc-cli-" + tag + "-" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}
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
