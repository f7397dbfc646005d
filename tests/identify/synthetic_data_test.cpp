// The identifier's synthetic data follow the truth's overrides as far as the FE model can: a
// sensor's bias and drift are added as the Simbody truth adds them; a servo lag, which the FE
// model cannot produce, is refused with one line naming the field.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "scoleid/identify/run/problem.h"
#include "scoleid/io/error.h"

using namespace scoleid;

TEST(SyntheticData, SensorBiasAndDriftOfTheTruthAreAddedExactly) {
  const std::string base = R"(structure: beam
beam: {length: 10, left: pinned, right: pinned, rho_A: 67, EI: 23000}
inputs: [{name: P, location: 5, signal: {type: step, amplitude: 10}}]
sensors: [{name: w_mid, location: 5}]
simulation: {duration: 1, sample_interval: 0.01}
identification: {parameterization: paper, estimate: [q1, q2], initial: {rho_A: 63, EI: 19000}}
)";
  const auto plain = identify::make_problem(io::parse_scenario(base, "plain"), std::nullopt);
  const auto biased = identify::make_problem(
      io::parse_scenario(base + "truth: {overrides: {sensors: [{name: w_mid, bias: 0.001, drift: -0.0003}]}}\n", "biased"),
      std::nullopt);
  ASSERT_EQ(plain->data.t.size(), biased->data.t.size());
  double worst = 0.0;
  for (std::size_t k = 0; k < plain->data.t.size(); ++k) {
    const auto i = static_cast<Eigen::Index>(k);
    const double expected = 0.001 - 0.0003 * plain->data.t[k];
    worst = std::max(worst, std::abs(biased->data.z(i, 0) - plain->data.z(i, 0) - expected));
  }
  EXPECT_LT(worst, 1e-15);
}

TEST(SyntheticData, ServoLagOfTheTruthIsRefusedNamingTheField) {
  const std::string sc = R"(structure: scole
inputs: [{name: F, at: actuator1, direction: y, signal: {type: haversine, amplitude: 0.1, width: 1}}]
sensors: [{name: tip, at: mast, location: 130, direction: y}]
simulation: {duration: 2, sample_interval: 0.01}
identification: {estimate: [EI], initial: {EI: 3.6e7}}
truth: {overrides: {scole: {actuator_lag: 0.02}}}
)";
  try {
    identify::make_problem(io::parse_scenario(sc, "lagged.yaml"), std::nullopt);
    FAIL() << "a truth-only servo lag was synthesised";
  } catch (const io::InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("lagged.yaml"), std::string::npos) << m;
    EXPECT_NE(m.find("truth.overrides.scole.actuator_lag"), std::string::npos) << m;
    EXPECT_NE(m.find("--data"), std::string::npos) << m;
  }
}
