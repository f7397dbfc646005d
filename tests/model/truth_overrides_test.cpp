// A mismatch scenario end to end: the Simbody truth built with truth.overrides (the reflector's
// CM offset 5 % larger than the identifier's model), then the FE identifier on its files. The
// truth records the values it used; the identifier's estimates move far beyond the chain's own
// lumping bias — the size of the mismatch, measured, not hidden.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "scoleid/io/data_files.h"
#include "scoleid/io/scenario.h"

namespace fs = std::filesystem;

namespace {
int sh(const std::string& cmd) {
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}
nlohmann::json read_json(const fs::path& p) {
  std::ifstream in(p);
  return nlohmann::json::parse(in);
}
double worst_error(const nlohmann::json& identify) {
  double w = 0.0;
  for (const auto& p : identify["parameters"]) w = std::max(w, std::abs(p["relative_error"].get<double>()));
  return w;
}
}  // namespace

TEST(TruthOverrides, ReflectorOffsetMismatchEndToEnd) {
  const fs::path dir = fs::temp_directory_path() / ("scoleid-overrides-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::string base = scoleid::io::builtin_scenario_yaml("paper-scole-1");
  base.replace(base.find("truth: {segments: 40}"), 21, "truth: {segments: 10}");
  const scoleid::io::Scenario nominal = scoleid::io::parse_scenario(base, "paper-scole-1");
  const double rx = 1.05 * nominal.scole.reflector_rx, ry = 1.05 * nominal.scole.reflector_ry;
  std::ostringstream ov;
  ov.precision(17);
  ov << base.substr(0, base.find("truth: {segments: 10}")) << "truth:\n  segments: 10\n  overrides:\n    scole: {reflector_rx: "
     << rx << ", reflector_ry: " << ry << "}\n";
  std::ofstream(dir / "base.yaml") << base;
  std::ofstream(dir / "ov.yaml") << ov.str();
  for (const char* c : {"base", "ov"}) {
    const std::string d = (dir / c).string();
    ASSERT_EQ(sh(std::string(SCOLE_TRUTH_EXE) + " --quiet --scenario " + d + ".yaml --out " + d + "/truth"), 0) << c;
    ASSERT_EQ(sh(std::string(SCOLE_IDENTIFY_EXE) + " -q --scenario " + d + ".yaml --data " + d + "/truth/truth.csv --out " + d +
                 "/identify > /dev/null 2>&1"),
              0)
        << c;
  }
  // The truth says what it simulated.
  const auto meta = read_json(dir / "ov" / "truth" / "truth.json");
  EXPECT_DOUBLE_EQ(meta["settings"]["truth"]["overrides"]["scole"]["reflector_rx"].get<double>(), rx);
  EXPECT_DOUBLE_EQ(meta["settings"]["scole"]["reflector_rx"].get<double>(), nominal.scole.reflector_rx);
  // The bias of the mismatched run dwarfs the matched run's (chain lumping at n = 10).
  const double matched = worst_error(read_json(dir / "base" / "identify" / "identify.json"));
  const double mismatched = worst_error(read_json(dir / "ov" / "identify" / "identify.json"));
  std::printf("worst relative parameter error: matched %.3e, reflector offset +5 %% in the truth %.3e\n", matched, mismatched);
  EXPECT_LT(matched, 2e-2);
  EXPECT_GT(mismatched, 3.0 * matched);
  fs::remove_all(dir);
}
