// run_truth (truth.csv / truth.json contents): Gaussian sensor noise with the scenario's std and
// seed on outputs only, reproducible for a seed; columns and metadata copied from the scenario;
// the "auto" integrator choice follows the chain's spectrum.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "scoleid/io/scenario.h"
#include "scoleid/model/truth_run.h"

using namespace scoleid;
using namespace scoleid::model;

namespace {

io::Scenario beam(double noise, unsigned seed) {
  const std::string yaml = R"(name: noise-beam
structure: beam
beam: {length: 10, left: clamped, right: free, rho_A: 67, EI: [23000, 30000], zeta: 0}
inputs:
  - {name: P, kind: force, location: 10, unit: N, signal: {type: haversine, amplitude: 10, t0: 0.1, width: 0.5}}
  - {name: M, kind: moment, location: 5, unit: N m, signal: {type: sine, amplitude: 3, frequency: 0.7}}
sensors:
  - {name: w_tip, location: 10, unit: m, noise_std: )" + std::to_string(noise) + R"(}
  - {name: slope_mid, kind: rotation, location: 5, unit: rad}
simulation: {duration: 2, sample_interval: 0.002, seed: )" + std::to_string(seed) + R"(}
truth: {segments: 10, integrator: rk-merson, accuracy: 1e-8}
)";
  return io::parse_scenario(yaml, "test");
}

}  // namespace

TEST(TruthRun, NoiseIsGaussianWithTheScenarioStdOnOutputsOnlyAndSeeded) {
  const double sd = 1e-4;
  const TruthResult clean = run_truth(beam(0.0, 7));
  const TruthResult a = run_truth(beam(sd, 7));
  const TruthResult b = run_truth(beam(sd, 7));
  const TruthResult c = run_truth(beam(sd, 8));
  ASSERT_EQ(a.table.names, (std::vector<std::string>{"P", "M", "w_tip", "slope_mid"}));
  const std::size_t N = a.table.t.size();
  ASSERT_EQ(N, 1001u);
  double mean = 0, var = 0;
  for (std::size_t i = 0; i < N; ++i) {
    EXPECT_EQ(a.table.columns[0][i], clean.table.columns[0][i]);
    EXPECT_EQ(a.table.columns[1][i], clean.table.columns[1][i]);
    EXPECT_EQ(a.table.columns[3][i], clean.table.columns[3][i]);   // noise_std 0: untouched
    EXPECT_EQ(a.table.columns[2][i], b.table.columns[2][i]);        // same seed, same data
    const double e = a.table.columns[2][i] - clean.table.columns[2][i];
    mean += e / N;
    var += e * e / N;
  }
  var -= mean * mean;
  // N = 1001 samples: the sample std is within 3 sigma = 3/sqrt(2N) = 6.7 % of sd, the mean
  // within 3 sd/sqrt(N).
  EXPECT_NEAR(std::sqrt(var) / sd, 1.0, 0.067);
  EXPECT_LT(std::abs(mean), 3 * sd / std::sqrt(double(N)));
  EXPECT_NE(a.table.columns[2][100], c.table.columns[2][100]);
  // Inputs are the signals at the sample times.
  EXPECT_DOUBLE_EQ(a.table.columns[1][250], 3 * std::sin(2 * M_PI * 0.7 * a.table.t[250]));
}

TEST(TruthRun, MetadataCopiesTheScenario) {
  const TruthResult r = run_truth(beam(1e-4, 3));
  const auto& m = r.meta;
  ASSERT_EQ(m.columns.size(), 4u);
  EXPECT_EQ(m.columns[1].kind, "input");
  EXPECT_EQ(m.columns[1].quantity, "moment");
  EXPECT_EQ(m.columns[1].unit, "N m");
  EXPECT_EQ(m.columns[2].kind, "output");
  EXPECT_EQ(m.columns[2].noise_std, 1e-4);
  EXPECT_EQ(m.columns[3].quantity, "rotation");
  EXPECT_EQ(m.columns[3].location, 5.0);
  EXPECT_EQ(m.true_parameters.at("EI_1"), 23000.0);
  EXPECT_EQ(m.true_parameters.at("EI_2"), 30000.0);
  EXPECT_EQ(m.true_parameters.count("EI"), 0u);
  EXPECT_EQ(m.generator.at("segments"), 10);
  EXPECT_EQ(m.generator.at("seed"), 3);
  EXPECT_EQ(m.settings.at("beam").at("EI").size(), 2u);
}

// Kelvin–Voigt damping (paper-beam-2, c_kv = 2·0.1·√(ρA·EI)) overdamps the chain's top modes: "auto" takes
// BDF. SCOLE's zeta leaves them ringing: the trapezoidal rule. Simple supports are constraints,
// which the trapezoidal rule does not project onto: explicit RK (paper-beam-1, -3).
TEST(TruthRun, AutoIntegratorFollowsTheSpectrum) {
  for (const auto& [name, expect] : std::vector<std::pair<std::string, std::string>>{
           {"paper-beam-1", "rk-merson"}, {"paper-beam-2", "cpodes"}, {"paper-beam-3", "rk-merson"},
           {"paper-scole-1", "trapezoidal"}, {"scole-slew", "trapezoidal"}}) {
    const io::Scenario sc = io::load_scenario(name);
    const auto st = prepare_structure(sc, 20);
    EXPECT_EQ(choose_integrator(st->system(), st->system().getDefaultState()), expect) << name;
  }
}
