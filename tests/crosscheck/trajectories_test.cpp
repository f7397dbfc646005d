// scole-crosscheck trajectories (crosscheck/trajectories.h): every input kind and every sensor kind
// of SCOLE through the Simbody chain and the FE model at the same parameters.
#include "scoleid/crosscheck/trajectories.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <set>

#include "scoleid/io/scenario.h"

using namespace scoleid;
namespace fs = std::filesystem;

TEST(Trajectories, EveryInputAndSensorKindAgreesAndImprovesWithSegments) {
  const io::Scenario sc = io::load_scenario(COVERAGE_SCENARIO);
  std::set<std::string> inputs, sensors;
  for (const auto& in : sc.inputs)
    inputs.insert((io::actuator_index(in.at) >= 0 ? std::string("actuator") : io::to_string(in.at)) + " " + io::to_string(in.kind));
  for (const auto& s : sc.sensors) sensors.insert(io::to_string(s.kind));
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

TEST(Trajectories, CantileverConvergesAtSecondOrderInTheLinearRangeOnly) {
  // paper-beam-2's 10 N tip step deflects the tip by 2.8 % of L: the geometrically exact chain then
  // differs from the linear FE by about 5e-4 whatever n (measured 0.032, 0.039, 0.051 % at n = 40,
  // 80, 160). With the load divided by 1e3 the difference is the chain's lumping alone and falls
  // at second order (measured 7.4e-4, 1.8e-4, 4.6e-5; rates 2.03, 1.96).
  const fs::path dir = fs::temp_directory_path() / ("scoleid-xc-cant-" + std::to_string(::getpid()));
  io::Scenario sc = io::load_scenario("paper-beam-2");
  crosscheck::TrajectoryOptions o;
  fs::remove_all(dir);
  const auto large = crosscheck::compare_trajectories(sc, o, dir.string());
  fs::remove_all(dir);
  for (auto& in : sc.inputs) {
    auto terms = in.signal.terms();
    for (auto& term : terms) term.amplitude *= 1e-3;
    in.signal = io::Signal(terms);
  }
  const auto small = crosscheck::compare_trajectories(sc, o, dir.string());
  fs::remove_all(dir);
  ASSERT_EQ(small.sensors.size(), 1u);
  const auto& d = small.sensors[0].relative_rms;
  ASSERT_EQ(d.size(), 3u);
  EXPECT_NEAR(std::log2(d[0] / d[1]), 2.0, 0.3);
  EXPECT_NEAR(std::log2(d[1] / d[2]), 2.0, 0.3);
  EXPECT_LT(d[2], 1e-4);
  EXPECT_GT(large.sensors[0].relative_rms[2], 3e-4);  // the nonlinearity, seen
}

TEST(Trajectories, TheNonlinearModelFollowsTheSlewWhereTheLinearOneDeparts) {
  // scole-slew: a 20° roll slew of the whole configuration. The linear FE model misses the
  // rotating frame's inertial coupling; the nonlinear one (fe/scole_nonlinear.h) carries it, with
  // the proof masses' slider planes turning with the mast (the free proof masses drift 36 ft) and
  // the mast's kinematics to second order; what it leaves is third order in the mast's
  // deflection (tip deflections of 1.7 % of L) and the chain's lumping (docs/theory.md §11.2).
  // Without the proof-mass term the roll tip was barely closer than with the linear model.
  // An 80-segment chain: against the chain extrapolated in n the nonlinear model's roll tip is
  // 0.004 % off, so its difference to a chain is that chain's lumping — 0.21 % at n = 40, a fifth
  // of the linear model's slew bias there, 0.058 % at n = 80.
  const fs::path dir = fs::temp_directory_path() / ("scoleid-xc-slew-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const io::Scenario sc = io::load_scenario("scole-slew");
  crosscheck::TrajectoryOptions o;
  o.segments = 80;
  o.levels = 1;
  o.nonlinear = true;
  o.nonlinear_elements = sc.identification.elements;
  const auto r = crosscheck::compare_trajectories(sc, o, dir.string());
  fs::remove_all(dir);
  ASSERT_EQ(r.nonlinear_elements, sc.identification.elements);
  double worst_linear = 0, worst_nonlinear = 0;
  for (const auto& s : r.sensors) {
    ASSERT_EQ(s.nonlinear_relative_rms.size(), 1u);
    const double lin = s.relative_rms[0], non = s.nonlinear_relative_rms[0];
    std::printf("  %-10s linear %.3e  nonlinear %.3e\n", s.name.c_str(), lin, non);
    if (s.kind == "acceleration") {  // the chain's lumped high modes weigh on both
      EXPECT_LT(non, lin) << s.name;
      continue;
    }
    // The slew bias: every displacement-type sensor at least 5 times closer to the chain.
    EXPECT_GT(lin, 5 * non) << s.name;
    worst_linear = std::max(worst_linear, lin);
    worst_nonlinear = std::max(worst_nonlinear, non);
  }
  EXPECT_GT(worst_linear, 5 * worst_nonlinear);
}

TEST(Trajectories, OnASmallSlewTheChainConvergesOntoTheNonlinearModelAtSecondOrder) {
  // scole-slew at a tenth of the moment (a 2° slew): the nonlinear model is complete to second
  // order in the deflection and the slew rate, so the chain's differences to it are its lumping
  // alone and fall at second order with n (measured: rates 1.98 for every displacement-type
  // sensor, differences 5.1e-4 to 6.2e-4 at n = 80). A missing second-order term shows as a floor
  // that lowers the rate once it exceeds about a third of the n = 80 chain's lumping (2e-4 here):
  // without the mast's second-order rotation the pitch tip's rate was 1.03. Smaller omissions pass
  // (docs/theory.md §3.8 compares amplitudes for those).
  // The linear model stays 3 % off the pitch tip's response to the slew, whatever n.
  const fs::path dir = fs::temp_directory_path() / ("scoleid-xc-slew2-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  io::Scenario sc = io::load_scenario("scole-slew");
  for (auto& in : sc.inputs) {
    auto terms = in.signal.terms();
    for (auto& term : terms) term.amplitude *= 0.1;
    in.signal = io::Signal(terms);
  }
  crosscheck::TrajectoryOptions o;
  o.levels = 2;
  o.nonlinear = true;
  o.nonlinear_elements = sc.identification.elements;
  const auto r = crosscheck::compare_trajectories(sc, o, dir.string());
  fs::remove_all(dir);
  double worst_linear = 0, worst_nonlinear = 0;
  for (const auto& s : r.sensors) {
    if (s.kind == "acceleration") continue;  // the chain's lumped high modes: rate 1.7
    SCOPED_TRACE(s.name);
    ASSERT_EQ(s.nonlinear_relative_rms.size(), 2u);
    const auto& d = s.nonlinear_relative_rms;
    std::printf("  %-10s nonlinear %.3e %.3e (rate %.2f)  linear %.3e\n", s.name.c_str(), d[0], d[1], std::log2(d[0] / d[1]),
                s.relative_rms[1]);
    EXPECT_NEAR(std::log2(d[0] / d[1]), 2.0, 0.3);
    worst_linear = std::max(worst_linear, s.relative_rms[1]);
    worst_nonlinear = std::max(worst_nonlinear, d[1]);
  }
  EXPECT_GT(worst_linear, 10 * worst_nonlinear);
}
