// scole-crosscheck modes (crosscheck/modes.h): the Simbody chain's natural frequencies converge
// at the Hencky lumping's rate to the Euler–Bernoulli values, the FE's at rate 4, and both agree
// with the closed form; on SCOLE the chain and FE agree after extrapolation, and the remaining
// difference of the higher modes is the chain's bending rotary inertia (docs/theory.md §11.1).
#include "scoleid/crosscheck/modes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "scoleid/identify/fe/modal.h"
#include "scoleid/identify/fe/structure.h"
#include "scoleid/identify/inverse/modal_misfit.h"
#include "scoleid/identify/inverse/optimizers.h"
#include "scoleid/io/scenario.h"

using namespace scoleid;
using crosscheck::compare_modes;
using crosscheck::ModesOptions;

namespace {
ModesOptions five() {
  ModesOptions o;
  o.count = 5;
  return o;
}
}  // namespace

TEST(Modes, PinnedBeamChainAndFeAgainstTheClosedForm) {
  const auto r = compare_modes(io::load_scenario("paper-beam-1"), five());
  ASSERT_EQ(r.modes.size(), 5u);
  EXPECT_FALSE(r.analytic.empty());
  for (const auto& m : r.modes) {
    SCOPED_TRACE("mode " + std::to_string(m.index));
    // Richardson from 80 and 160 segments leaves O(n^-4): measured <= 2e-7 relative.
    EXPECT_NEAR(m.chain_extrapolated / m.analytic_hz, 1.0, 2e-6);
    // Cubic Hermite FE on 40 elements: measured <= 2e-5 (mode 5); rate 4 in N.
    EXPECT_NEAR(m.fe_hz.back() / m.analytic_hz, 1.0, 5e-5);
    EXPECT_NEAR(m.fe_rate, 4.0, 0.3);
    EXPECT_GE(m.mac, 0.99);
    EXPECT_EQ(m.best_fe, m.index);
  }
}

TEST(Modes, CantileverChainConvergesAtSecondOrder) {
  const auto r = compare_modes(io::load_scenario("paper-beam-2"), five());
  ASSERT_EQ(r.modes.size(), 5u);
  for (const auto& m : r.modes) {
    SCOPED_TRACE("mode " + std::to_string(m.index));
    // The Hencky chain of a clamped-free beam: O(n^-2) (measured 2.00-2.01).
    EXPECT_NEAR(m.chain_rate, 2.0, 0.1);
    // Extrapolated: measured <= 1.1e-5 from the finest FE, closed form likewise.
    EXPECT_NEAR(m.extrapolated_difference(), 0.0, 1e-4 * 0.5);
    EXPECT_NEAR(m.chain_extrapolated / m.analytic_hz, 1.0, 5e-5);
    EXPECT_GE(m.mac, 0.99);
  }
}

TEST(Modes, ScoleChainAndFeAgreeAfterExtrapolation) {
  const auto r = compare_modes(io::load_scenario("paper-scole-1"), five());
  ASSERT_EQ(r.modes.size(), 5u);
  EXPECT_TRUE(r.analytic.empty());  // no closed form for the offset reflector
  for (const auto& m : r.modes) {
    SCOPED_TRACE("mode " + std::to_string(m.index));
    EXPECT_NEAR(m.chain_rate, 2.0, 0.2);
    // The bound: 0.1 % (measured 0.009-0.069 %, growing with the mode number).
    EXPECT_LT(std::abs(m.extrapolated_difference()), 1e-3);
    EXPECT_GE(m.mac, 0.99);
  }
}

TEST(Modes, ScoleChainAndFEAgreeWhenBothCarryTheSectionsRotaryInertia) {
  // Both sides model the section's bending rotary inertia ρI_ψ/2 per length (the chain's rigid
  // segments always carry it; the FE's Rayleigh term, scole.bending_rotary_inertia): the
  // extrapolated chain then meets the finest FE to the extrapolation's own error. An
  // Euler–Bernoulli FE (the term off) misses it by more than 1e-3 by mode 6.
  io::Scenario sc = io::load_scenario("paper-scole-1");
  ModesOptions o;
  o.count = 6;
  const auto with = compare_modes(sc, o);
  ASSERT_EQ(with.modes.size(), 6u);
  for (const auto& m : with.modes) {
    std::printf("  mode %d: extrapolated chain / FE - 1 = %+.3e; damping ratio chain %.6f, FE %.6f\n", m.index,
                m.extrapolated_difference(), m.chain_zeta, m.fe_zeta);
    // Measured at most 2e-7 for these six modes (4e-6 by the tenth).
    EXPECT_LT(std::abs(m.extrapolated_difference()), 1e-6) << "mode " << m.index;
  }
  io::Scenario eb = sc;
  eb.scole.bending_rotary_inertia = false;
  namespace identify = scoleid::identify;
  const auto fe = identify::make_structure(eb, with.elements.back());
  const auto ops = identify::assemble(fe->model(), fe->coefficients(eb));
  const auto nm = identify::natural_modes(ops.M, ops.K);
  std::vector<double> hz;
  for (int i = 0; i < nm.omega.size(); ++i)
    if (nm.omega[i] > nm.floor) hz.push_back(nm.omega[i] / (2 * M_PI));
  const double gap = with.modes[5].chain_extrapolated / hz[5] - 1.0;
  std::printf("  mode 6 against an Euler-Bernoulli FE: %+.3e\n", gap);
  EXPECT_LT(gap, -1e-3);
}

TEST(Modes, ScoleModalDampingRatiosAgreeBetweenChainAndFE) {
  // The same square-root damping on both sides (docs/theory.md §3.3): the first ten modes'
  // damping ratios agree to the discretisation level, and the first bending pair carries a
  // ratio of order ζ (part of its kinetic energy sits in the undamped end bodies).
  io::Scenario sc = io::load_scenario("paper-scole-1");
  ModesOptions o;
  o.count = 10;
  o.levels = 1;
  const auto r = compare_modes(sc, o);
  ASSERT_EQ(r.modes.size(), 10u);
  std::printf("  mode   f chain [Hz]   zeta chain   zeta FE    rel. diff\n");
  for (const auto& m : r.modes) {
    const double d = m.chain_zeta / m.fe_zeta - 1.0;
    std::printf("  %4d %13.6f %12.6f %10.6f %+11.3e\n", m.index, m.chain_hz[0], m.chain_zeta, m.fe_zeta, d);
    ASSERT_TRUE(std::isfinite(m.chain_zeta) && std::isfinite(m.fe_zeta)) << "mode " << m.index;
    // Measured at most 0.4 % at n = 40 (falling at second order in n).
    EXPECT_LT(std::abs(d), 0.01) << "mode " << m.index;
    EXPECT_GT(m.fe_zeta, 0.1 * sc.scole.zeta) << "mode " << m.index;
    EXPECT_LT(m.fe_zeta, 1.05 * sc.scole.zeta) << "mode " << m.index;
  }
}

// The chain's modes as measured modes (crosscheck::chain_modal_data, docs/theory.md §6.6): the
// stds are the chain's own lumping error, so the FE model at the truth's parameters explains them
// (χ² within its band), and EI, ρA identified from them land within the lumping level.
TEST(ChainModalData, StdsAreTheLumpingErrorAndTheModesIdentifyTheMast) {
  const io::Scenario sc = io::load_scenario(std::string(SCOLEID_SOURCE_DIR) + "/identify/examples/modal/scole-modal.yaml");
  const io::ModalData d = crosscheck::chain_modal_data(sc, sc.truth.segments, 6);
  ASSERT_EQ(d.modes.size(), 6u);
  ASSERT_EQ(d.stations.size(), 4u);
  double worst = 0.0;  // largest relative frequency std
  for (const auto& m : d.modes) {
    EXPECT_GT(m.frequency_std_hz, 0.0);
    EXPECT_GT(m.shape_std, 0.0);
    worst = std::max(worst, m.frequency_std_hz / m.frequency_hz);
  }
  const auto fe = identify::make_structure(sc, sc.identification.elements);
  const auto params = fe->parameterize(sc);
  identify::ModalMisfit misfit(fe->model(), *params, d);
  Eigen::VectorXd r;
  misfit.residuals(params->truth(), r);
  const double N = static_cast<double>(r.size());
  std::printf("chain modal data: %zu modes, largest relative frequency std %.3e, chi2 at the truth %.3g (N = %g)\n",
              d.modes.size(), worst, r.squaredNorm(), N);
  EXPECT_LT(r.squaredNorm(), N + 3.0 * std::sqrt(2.0 * N));
  identify::OptimizerOptions oo;
  oo.method = scoleid::io::Method::GaussNewton;
  const auto s = identify::minimize(misfit, params->initial(), oo);
  ASSERT_TRUE(s.converged()) << s.message;
  const Eigen::VectorXd t = params->truth();
  for (Eigen::Index i = 0; i < t.size(); ++i) {
    const double e = s.q[i] / t[i] - 1.0;
    std::printf("  %s: relative error %.3e\n", params->names()[static_cast<std::size_t>(i)].c_str(), e);
    // A frequency known to δ relative fixes a stiffness-to-mass ratio to 2δ.
    EXPECT_LT(std::abs(e), 2.0 * worst);
  }
}
