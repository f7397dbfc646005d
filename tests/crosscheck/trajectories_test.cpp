// scole-crosscheck trajectories (crosscheck/trajectories.h): every input kind and every sensor kind
// of SCOLE through the Simbody chain and the FE model at the same parameters.
#include "scoleid/crosscheck/trajectories.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <set>

#include "scoleid/io/scenario.h"

using namespace scoleid;
namespace fs = std::filesystem;

TEST(Trajectories, EveryInputAndSensorKindAgreesAndImprovesWithSegments) {
  const io::Scenario sc = io::load_scenario(COVERAGE_SCENARIO);
  std::set<std::string> inputs, sensors;
  for (const auto& in : sc.inputs) inputs.insert(in.at.rfind("actuator", 0) == 0 ? "actuator " + in.kind : in.at + " " + in.kind);
  for (const auto& s : sc.sensors) sensors.insert(s.kind);
  EXPECT_EQ(inputs, (std::set<std::string>{"shuttle force", "shuttle moment", "reflector force", "reflector moment",
                                           "mast force", "actuator force"}));
  EXPECT_EQ(sensors, (std::set<std::string>{"displacement", "rotation", "line_of_sight", "velocity", "acceleration"}));

  const fs::path dir = fs::temp_directory_path() / ("scoleid-xc-traj-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  crosscheck::TrajectoryOptions o;
  o.levels = 3;  // 10, 20, 40 segments
  const auto r = crosscheck::compare_trajectories(sc, o, dir.string());
  fs::remove_all(dir);
  ASSERT_EQ(r.sensors.size(), sc.sensors.size());
  for (const auto& s : r.sensors) {
    SCOPED_TRACE(s.name);
    ASSERT_EQ(s.relative_rms.size(), 3u);
    const double finest = s.relative_rms.back();
    // Bounds at n = 40 from the measured values with a margin of about 1.5 (sharp 0.3 s pulses
    // excite modes the 40-segment chain lumps coarsely; measured: displacements 0.36 and 1.95 %,
    // rotation 0.83 %, line of sight 0.24 %, velocity 11.9 %, acceleration 82 %). The
    // accelerometer sees the chain's high modes, which the FE (and the continuum) place elsewhere.
    if (s.kind == "acceleration") {
      EXPECT_LT(finest, 1.2);
    } else if (s.kind == "velocity") {
      EXPECT_LT(finest, 0.18);
    } else {
      EXPECT_LT(finest, 0.03);
      // Displacement-type outputs improve at every refinement (measured rates 0.66-0.86).
      EXPECT_LT(s.relative_rms[1], s.relative_rms[0]);
      EXPECT_LT(s.relative_rms[2], s.relative_rms[1]);
    }
  }
}
