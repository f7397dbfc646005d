// The frame on the Simbody truth (docs/theory.md §2.6, the built-in frame-4storey): two columns a
// storey as Hencky chains, their heads closed onto rigid floor blocks. The chain's sway
// frequencies converge at second order onto the exact ones (the columns' dynamic stiffness) and
// the FE model's at fourth; from one hammer tap on the top floor read by four floor
// accelerometers, each storey's EI and the damping's time constant, the estimates off by what the
// chain's lumping makes its frequencies (0.25 % at 80 segments: EI by twice that) and the record's
// own first mode held by its interval.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "scoleid/crosscheck/modes.h"
#include "scoleid/identify.h"
#include "scoleid/model/truth_run.h"
#include "scoleid/identify/fe/analytic_frame.h"
#include "scoleid/model/linearisation.h"
#include "scoleid/truth.h"

using namespace scoleid;

TEST(FrameTruth, ChainAndFiniteElementsMeetTheExactFrequencies) {
  const io::Scenario sc = io::load_scenario("frame-4storey");
  crosscheck::ModesOptions mo;
  mo.count = 4;
  mo.segments = 40;  // 40, 80, 160 (at 640 the chain's linearisation by differences loses the sixth digit)
  const crosscheck::ModesReport r = crosscheck::compare_modes(sc, mo);
  ASSERT_EQ(r.modes.size(), 4u);
  ASSERT_FALSE(r.analytic.empty());
  const io::Scenario truth = io::truth_scenario(sc);
  const auto exact = identify::analytic::frame_omegas(truth.frame, 4);
  for (const auto& m : r.modes) {
    SCOPED_TRACE("mode " + std::to_string(m.index));
    std::printf("  mode %d: chain %.6f %.6f %.6f -> %.6f Hz, FE %.7f Hz, exact %.7f Hz, MAC %.4f\n", m.index, m.chain_hz[0],
                m.chain_hz[1], m.chain_hz[2], m.chain_extrapolated, m.fe_hz.back(), m.analytic_hz, m.mac);
    EXPECT_NEAR(m.analytic_hz, exact[static_cast<std::size_t>(m.index - 1)] / (2 * M_PI), 1e-12 * m.analytic_hz);
    // Second order in the segments: the differences fall by 4 (measured 3.9–4.0).
    const double rate = (m.chain_hz[1] - m.chain_hz[0]) / (m.chain_hz[2] - m.chain_hz[1]);
    EXPECT_GT(rate, 3.5);
    EXPECT_LT(rate, 4.5);
    // Extrapolated (measured within 3e-6), and the finest FE (64 elements; measured 2e-9).
    EXPECT_LT(std::abs(m.chain_extrapolated / m.analytic_hz - 1.0), 5e-5);
    EXPECT_LT(std::abs(m.fe_hz.back() / m.analytic_hz - 1.0), 1e-7);
    EXPECT_GE(m.mac, 0.99);
  }
}

// Three columns a storey (the third closed onto the floor along the sway only), storeys of unequal
// heights and stiffnesses: the chain still converges at second order onto the exact frequencies.
TEST(FrameTruth, ThreeColumnsAndUnequalStoreysMeetTheExactFrequencies) {
  const io::Scenario sc = io::parse_scenario(R"(name: three-columns
structure: frame
frame: {heights: [0.4, 0.25, 0.3], columns: 3, bay: 0.15, rho_A: 0.3, EI: [4.0, 2.5, 3.0], floor_mass: [1.5, 1.2, 0.9]}
inputs: [{name: F, at: frame, kind: force, location: 0.95, signal: {type: haversine, amplitude: 10, t0: 0, width: 0.01}}]
sensors: [{name: a, at: frame, kind: acceleration, location: 0.95}, {name: r, at: frame, kind: rotation, location: 0.5}]
)", "three-columns");
  crosscheck::ModesOptions mo;
  mo.count = 3;
  mo.segments = 40;
  const crosscheck::ModesReport r = crosscheck::compare_modes(sc, mo);
  ASSERT_EQ(r.modes.size(), 3u);
  for (const auto& m : r.modes) {
    SCOPED_TRACE("mode " + std::to_string(m.index));
    std::printf("  mode %d: chain %.6f %.6f %.6f -> %.6f Hz, FE %.7f Hz, exact %.7f Hz, MAC %.4f\n", m.index, m.chain_hz[0],
                m.chain_hz[1], m.chain_hz[2], m.chain_extrapolated, m.fe_hz.back(), m.analytic_hz, m.mac);
    const double rate = (m.chain_hz[1] - m.chain_hz[0]) / (m.chain_hz[2] - m.chain_hz[1]);
    EXPECT_GT(rate, 3.0);  // 3.5–3.8 measured: 10 to 16 segments a storey at 40 are not yet asymptotic
    EXPECT_LT(rate, 4.5);
    EXPECT_LT(std::abs(m.chain_extrapolated / m.analytic_hz - 1.0), 5e-5);
    EXPECT_LT(std::abs(m.fe_hz.back() / m.analytic_hz - 1.0), 1e-7);
    EXPECT_GE(m.mac, 0.99);
  }
}

TEST(FrameTruth, OneHammerTapGivesEachStoreysStiffnessAndTheDamping) {
  const io::Scenario sc = io::load_scenario("frame-4storey");
  const Truth truth = simulate_truth(sc);
  const Identification id = identify_parameters(sc, DataSource::in_memory(truth.table, "frame truth", truth.meta), {});
  std::printf("%s", id.FullReport().c_str());
  ASSERT_TRUE(id.converged()) << id.verdict();
  const auto& r = id.result();
  ASSERT_EQ(r.names.size(), 5u);
  for (std::size_t i = 0; i < r.names.size(); ++i) {
    const auto e = static_cast<Eigen::Index>(i);
    const double t = r.truth.at(r.names[i]);
    // The chain's lumping lowers its sway frequencies by 0.25 % at 80 segments: the storeys' EI by
    // about twice that (measured 0.44–0.57 %); the damping's time constant is free of it.
    EXPECT_LT(std::abs(r.estimate[e] / t - 1.0), r.names[i] == "tau" ? 2e-3 : 1e-2) << r.names[i];
  }
  // The identified model's modes against the chain's own (linearised at its 80 segments): the
  // record's truth, each within the mode's interval (which holds what the model's form misses).
  const auto bare = model::build_structure(io::truth_scenario(sc), sc.truth.segments);
  bare->system().realizeTopology();
  const auto chain = model::natural_modes(bare->system(), bare->system().getDefaultState());
  ASSERT_GE(r.modes.size(), 4u);
  ASSERT_GE(chain.size(), 4u);
  for (std::size_t k = 0; k < 4; ++k) {
    const auto& m = r.modes[k];
    std::printf("  mode %zu: model %.6f ± %.2e Hz, chain %.6f Hz\n", k + 1, m.frequency_hz, m.frequency_half_width_hz,
                chain[k].frequency_hz);
    EXPECT_LE(std::abs(m.frequency_hz - chain[k].frequency_hz), m.frequency_half_width_hz) << "mode " << k + 1;
  }
}
