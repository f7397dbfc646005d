// The truth's plausibility guards (docs/truth-guards.md): a run whose motion leaves the range of
// the identifier's linear model is refused — exit code 1, one line naming what, the bound and the
// time, and nothing written — instead of being written as data.
//   * proof-mass stroke: a force with net impulse on a free proof mass sets it drifting along its
//     slider; it is caught at the first sample past the stroke. A zero-net-impulse doublet of small
//     amplitude keeps it within the stroke and passes; the guard is on the displacement, so the same
//     doublet at ten times the amplitude is refused too.
//   * small rotations: a shuttle roll beyond the bound (or a beam segment's rotation) is refused
//     unless the scenario is a large-motion study (truth.large_motion: true).
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include "scoleid/io/data_files.h"
#include "scoleid/io/scenario.h"
#include "scoleid/model/truth_run.h"

#include "cli_fixture.h"
#include "common/test_data.h"

namespace fs = std::filesystem;
using namespace scoleid;

namespace {

using scoleid::model::test::CliResult;

class PlausibilityGuard : public scoleid::model::test::TruthCliFixture {
protected:
  // Nothing but the inputs the test wrote (scenario files, stderr.txt): no output directory, no
  // staging directory left behind.
  void expect_nothing_written() {
    for (const auto& e : fs::directory_iterator(dir_)) {
      const std::string n = e.path().filename().string();
      EXPECT_TRUE(e.is_regular_file() && (n == "stderr.txt" || e.path().extension() == ".yaml"))
          << "left behind: " << e.path();
    }
  }
  static int lines(const std::string& s) { return static_cast<int>(std::count(s.begin(), s.end(), '\n')); }

};

// The number after `key` in a message ("t = 0.55 s" -> 0.55), NaN if absent.
double number_after(const std::string& msg, const std::string& key) {
  const auto at = msg.find(key);
  if (at == std::string::npos) return std::nan("");
  return std::strtod(msg.c_str() + at + key.size(), nullptr);
}

// SCOLE driven by actuator 1 along y only (the default actuators at L/3 and 2L/3, the default
// stroke), cheap: 4 segments, 2 s.
std::string actuator_scenario(const std::string& signal, const std::string& extra = "") {
  return scoleid::test::test_scenario("plausibility_guard_test/guard-actuator") +
         signal + R"(}
sensors:
  - {name: roll_tip, at: mast, kind: displacement, location: 130, direction: y, unit: ft}
simulation: {duration: 2, sample_interval: 0.01, seed: 1}
truth:
  segments: 4
)" + extra;
}

// A one-sided force pulse F on the 0.2 slug proof mass from t0 = 0.1 s: its displacement relative
// to the mast is F/(2m) (t - t0)^2 while the pulse lasts (the reaction on the 6400 slug
// structure moves the mast by 3e-5 of that), 0.5 ft at t = 0.1 + sqrt(0.2) = 0.547 s.
const char* kNetImpulse = "{type: pulse, amplitude: 1, t0: 0.1, width: 0.5}";

}  // namespace

TEST_F(PlausibilityGuard, ProofMassDriftBeyondTheStrokeExits1NamingActuatorStrokeAndTime) {
  const std::string file = write("drift.yaml", actuator_scenario(kNetImpulse));
  const fs::path out = dir_ / "out";
  const CliResult r = run("--scenario " + file + " --out " + out.string() + " --quiet");
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_EQ(lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find(file), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("actuator1 proof mass"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("stroke scole.actuator_stroke = 0.5"), std::string::npos) << r.err;
  // Caught at the first sample past the analytic crossing (0.547 s), at the value it has there.
  const double t = number_after(r.err, "at t = ");
  EXPECT_NEAR(t, 0.55, 1e-9) << r.err;
  const double d = number_after(r.err, "displaced ");
  EXPECT_NEAR(std::abs(d), 2.5 * (t - 0.1) * (t - 0.1), 1e-3) << r.err;
  EXPECT_GT(std::abs(d), 0.5) << r.err;
  EXPECT_FALSE(fs::exists(out));
  expect_nothing_written();

  // An earlier run in the target stays exactly as it was.
  const std::string quiet_file = write("quiet.yaml", actuator_scenario("{type: bangbang, amplitude: 0.1, t0: 0.1, width: 1}"));
  ASSERT_EQ(run("--scenario " + quiet_file + " --out " + out.string() + " --quiet").code, 0);
  const auto before = io::read_csv((out / "truth.csv").string());
  EXPECT_EQ(run("--scenario " + file + " --out " + out.string() + " --quiet").code, 1);
  EXPECT_EQ(io::read_csv((out / "truth.csv").string()).columns, before.columns);
}

TEST_F(PlausibilityGuard, ThroughRunTruthTheErrorIsAPlausibilityErrorAndNamesAnOverriddenStroke) {
  const io::Scenario sc = io::parse_scenario(actuator_scenario(kNetImpulse), "scenario 'drift.yaml'");
  EXPECT_THROW(model::run_truth(sc), model::PlausibilityError);
  // A stroke set for the truth alone is named as such; 0.3 ft is crossed at 0.1 + sqrt(0.12) = 0.446 s.
  const io::Scenario ov =
      io::parse_scenario(actuator_scenario(kNetImpulse, "  overrides: {scole: {actuator_stroke: 0.3}}\n"), "scenario 'ov.yaml'");
  try {
    model::run_truth(ov);
    FAIL() << "not refused";
  } catch (const model::PlausibilityError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("scenario 'ov.yaml': actuator1 proof mass"), std::string::npos) << m;
    EXPECT_NE(m.find("truth.overrides.scole.actuator_stroke = 0.3"), std::string::npos) << m;
    EXPECT_NEAR(number_after(m, "at t = "), 0.45, 1e-9) << m;
  }
}

TEST_F(PlausibilityGuard, ZeroNetImpulseDoubletOfSmallAmplitudePasses) {
  // Bang-bang (+A then -A over w): the proof mass ends at rest, A (w/2)^2 / m = 0.125 ft away.
  const std::string file = write("doublet.yaml", actuator_scenario("{type: bangbang, amplitude: 0.1, t0: 0.1, width: 1}"));
  const fs::path out = dir_ / "out";
  const CliResult r = run("--scenario " + file + " --out " + out.string() + " --quiet");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  const auto tab = io::read_csv((out / "truth.csv").string());
  EXPECT_EQ(tab.t.size(), 201u);
  // The guard is on the displacement, not the impulse: ten times the amplitude (1.25 ft) is refused.
  const io::Scenario big =
      io::parse_scenario(actuator_scenario("{type: bangbang, amplitude: 1, t0: 0.1, width: 1}"), "scenario 'big.yaml'");
  EXPECT_THROW(model::run_truth(big), model::PlausibilityError);
}

namespace {
// A steady roll moment M on the shuttle: the whole structure turns rigidly, theta = M t^2 / (2 I),
// I = 1.2044e6 slug ft^2 about the system CM, 0.1 rad at t = 2.004 s. The mast is 100 times
// stiffer than SCOLE's so that it bends by less than 1e-3 rad under the manoeuvre: the shuttle's
// attitude is the rotation that crosses the bound; the passive proof masses get the room the
// mast sweeps past them (s theta < 14 ft).
std::string roll_scenario(bool large_motion) {
  return std::string(scoleid::test::test_scenario("plausibility_guard_test/guard-roll")) +
         (large_motion ? ", large_motion: true" : "") + "}\n";
}
}  // namespace

TEST_F(PlausibilityGuard, RotationBeyondTheBoundIsRefusedUnlessLargeMotion) {
  const fs::path out = dir_ / "out";
  const std::string small = write("roll.yaml", roll_scenario(false));
  const CliResult r = run("--scenario " + small + " --out " + out.string() + " --quiet");
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_EQ(lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("shuttle attitude"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("small-rotation bound 0.1 rad"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("truth.large_motion"), std::string::npos) << r.err;
  // Caught at the first sample past the crossing (2.004 s for the rigid structure; the free proof
  // masses and the mast's small lag move it by about 1 ms).
  const double t = number_after(r.err, "at t = ");
  EXPECT_GE(t, 2.0) << r.err;
  EXPECT_LE(t, 2.02) << r.err;
  const double angle = number_after(r.err, "rotated ");
  EXPECT_GT(angle, model::kSmallRotationBound) << r.err;
  EXPECT_NEAR(angle, 60000.0 * t * t / (2 * 1.2044e6), 2e-3) << r.err;
  EXPECT_FALSE(fs::exists(out));
  expect_nothing_written();

  const std::string large = write("roll-large.yaml", roll_scenario(true));
  const CliResult ok = run("--scenario " + large + " --out " + out.string() + " --quiet");
  ASSERT_EQ(ok.code, 0) << ok.err;
  const auto tab = io::read_csv((out / "truth.csv").string());
  ASSERT_EQ(tab.names, (std::vector<std::string>{"M_roll", "roll"}));
  EXPECT_GT(tab.columns[1].back(), 1.5 * model::kSmallRotationBound);  // recorded, well past the bound
  EXPECT_EQ(io::read_truth_meta((out / "truth.json").string()).settings.at("truth").at("large_motion"), true);
}

TEST_F(PlausibilityGuard, BeamSegmentRotationRelativeToGroundIsBounded) {
  // Cantilever under a suddenly applied tip load: static tip slope P L^2 / (2 EI) = 0.22 rad.
  auto beam = [](const std::string& truth_extra) {
    return io::parse_scenario(scoleid::test::test_scenario("plausibility_guard_test/guard-beam") + truth_extra + "}\n",
                              "scenario 'beam.yaml'");
  };
  try {
    model::run_truth(beam(""));
    FAIL() << "not refused";
  } catch (const model::PlausibilityError& e) {
    const std::string m = e.what();
    EXPECT_TRUE(std::regex_search(m, std::regex("beam segment [0-9]+ of 4 \\(s = [0-9.]+ to [0-9.]+\\) relative to ground")))
        << m;
    EXPECT_GT(number_after(m, "rotated "), model::kSmallRotationBound) << m;
  }
  const model::TruthResult r = model::run_truth(beam(", large_motion: true"));
  EXPECT_EQ(r.table.t.size(), 301u);
}

// Every built-in stays within its guards (scole-slew as the large-motion study it declares);
// checked on a coarse chain for time, over the full record.
TEST_F(PlausibilityGuard, BuiltinsStayWithinTheirGuards) {
  for (const auto& name : io::builtin_scenario_names()) {
    io::Scenario sc = io::load_scenario(name);
    model::TruthOptions opt;
    opt.segments = 8;
    opt.accuracy = 1e-7;
    EXPECT_NO_THROW(model::run_truth(sc, opt)) << name;
  }
  EXPECT_TRUE(io::load_scenario("scole-slew").truth.large_motion);
  EXPECT_FALSE(io::load_scenario("paper-scole-1").truth.large_motion);
}
