// The identified model's modes and their uncertainty (inverse/modal_uncertainty.h):
//  - the propagated std and interval against the closed form of a uniform beam, whose every
//    frequency is ∝ √(EI/ρA) and whose square-root damping gives ratios ∝ ζ alone;
//  - a mode resting on a flagged parameter gets no uncertainty, and says why;
//  - the scatter of the identified first frequency over noise seeds against its propagated std, and
//    the interval covering the truth's frequency.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "scoleid/identify/inverse/modal_uncertainty.h"
#include "scoleid/identify/run/identify_run.h"
#include "test_support.h"
#include "common/test_data.h"

using namespace scoleid::identify;

namespace {

const std::string kUniformBeam = scoleid::test::test_scenario("modal_uncertainty_test/modal-beam");

// An assessment with a given covariance, systematic share and interval terms.
struct Assessment {
  Identifiability id;
  UncertaintyInterval iv;
};
Assessment assessment(const VectorXd& q) {
  Assessment a;
  const int P = static_cast<int>(q.size());
  MatrixXd L = MatrixXd::Zero(P, P);
  L << 0.03, 0, 0, 0.02, 0.01, 0, 0.1, -0.2, 0.15;  // relative, correlated
  const MatrixXd Crel = L * L.transpose();
  a.id.covariance = q.asDiagonal() * Crel * q.asDiagonal();
  a.id.std = a.id.covariance.diagonal().cwiseSqrt();
  a.id.resolution = a.id.std * std::sqrt(0.5);
  a.id.systematic = 0.5;
  a.id.identifiable.assign(static_cast<std::size_t>(P), true);
  a.id.reason.assign(static_cast<std::size_t>(P), "");
  a.iv.half_record_delta = VectorXd(P);
  a.iv.half_record_delta << 0.01 * q[0], -0.004 * q[1], 0.05 * q[2];
  ConsiderTerm t;
  t.field = "beam.length";
  t.shift = VectorXd(P);
  t.shift << -0.002 * q[0], 0.006 * q[1], -0.01 * q[2];
  a.iv.terms.push_back(t);
  return a;
}

}  // namespace

TEST(ModalUncertainty, PropagatedStdAndIntervalMatchTheUniformBeamsClosedForm) {
  auto c = test_support::make_case(kUniformBeam, false);
  const Problem& p = *c.p;
  const VectorXd q = p.params->truth();  // EI, rho_A, zeta
  const Assessment a = assessment(q);
  const auto modes = modal_estimates(p.model(), *p.params, q, a.id, a.iv);
  ASSERT_EQ(modes.size(), 10u);
  // f_n ∝ √(EI/ρA): ∂f/∂q = f (1/2EI, −1/2ρA, 0); ζ_n ∝ ζ: ∂ζ_n/∂q = (0, 0, ζ_n/ζ).
  for (const auto& m : modes) {
    ASSERT_TRUE(m.note.empty()) << m.note;
    VectorXd gf(3), gz(3);
    gf << m.frequency_hz / (2 * q[0]), -m.frequency_hz / (2 * q[1]), 0.0;
    gz << 0.0, 0.0, m.damping_ratio / q[2];
    const double sf = std::sqrt(gf.dot(a.id.covariance * gf)), sz = std::sqrt(gz.dot(a.id.covariance * gz));
    const double hf = 2 * sf * std::sqrt(1.5) + std::abs(gf.dot(a.iv.half_record_delta)) + std::abs(gf.dot(a.iv.terms[0].shift));
    const double hz = 2 * sz * std::sqrt(1.5) + std::abs(gz.dot(a.iv.half_record_delta)) + std::abs(gz.dot(a.iv.terms[0].shift));
    std::printf("  mode %2d  f %10.5f Hz  std %.4e (closed form %.4e)  zeta %.5f  std %.4e (%.4e)\n", m.mode, m.frequency_hz,
                m.frequency_std_hz, sf, m.damping_ratio, m.damping_std, sz);
    EXPECT_NEAR(m.frequency_std_hz, sf, 1e-6 * sf);
    EXPECT_NEAR(m.frequency_half_width_hz, hf, 1e-6 * hf);
    EXPECT_NEAR(m.damping_std, sz, 1e-6 * sz);
    EXPECT_NEAR(m.damping_half_width, hz, 1e-6 * hz);
  }
  // The lowest mode against the pinned beam's (π/L)² √(EI/ρA) / 2π.
  const double f1 = std::pow(M_PI / 2.0, 2) * std::sqrt(q[0] / q[1]) / (2 * M_PI);
  EXPECT_NEAR(modes[0].frequency_hz, f1, 1e-5 * f1);  // 12 Hermite elements: 3e-6
  // The square-root law's ratio is ζ in every mode of the continuous beam; the FE model's lowest
  // modes keep it to the discretisation error.
  EXPECT_NEAR(modes[0].damping_ratio, q[2], 1e-4 * q[2]);
}

TEST(ModalUncertainty, AModeOnAFlaggedParameterOrAboveNyquistIsNotGiven) {
  auto c = test_support::make_case(kUniformBeam, false);
  const Problem& p = *c.p;
  const VectorXd q = p.params->truth();
  Assessment a = assessment(q);
  a.id.identifiable[2] = false;  // zeta flagged: the frequencies stand, the damping ratios do not
  ModalUncertaintyOptions o;
  o.max_frequency_hz = 30.0;
  const auto modes = modal_estimates(p.model(), *p.params, q, a.id, a.iv, o);
  ASSERT_FALSE(modes.empty());
  for (const auto& m : modes) {
    EXPECT_LT(m.frequency_hz, 30.0);
    EXPECT_FALSE(std::isfinite(m.damping_std));
    EXPECT_FALSE(std::isfinite(m.frequency_std_hz));  // one mode, one verdict
    EXPECT_NE(m.note.find("zeta"), std::string::npos) << m.note;
  }
  // Without an assessment: values only, with the reason.
  const auto bare = modal_estimates(p.model(), *p.params, q, Identifiability{}, UncertaintyInterval{});
  ASSERT_FALSE(bare.empty());
  EXPECT_DOUBLE_EQ(bare[0].frequency_hz, modes[0].frequency_hz);
  EXPECT_FALSE(std::isfinite(bare[0].frequency_std_hz));
  EXPECT_FALSE(bare[0].note.empty());
}

// Paper Case I with 2 % noise: the first frequency's scatter over seeds against its propagated
// std, the intervals covering the truth's frequency, and the correlation matrix's form.
TEST(ModalUncertainty, FrequencyScatterOverSeedsMatchesItsPropagatedStd) {
  auto sc = scoleid::io::load_scenario("paper-beam-1");
  sc.sensors[0].noise_std = 0.02 * 0.018;
  const double L = sc.beam.length;
  const double f1_true = std::pow(M_PI / L, 2) * std::sqrt(sc.beam.EI[0] / sc.beam.rho_A) / (2 * M_PI);
  const int seeds = 32;
  std::vector<double> f;
  double std0 = 0;
  int covered = 0;
  for (int s = 0; s < seeds; ++s) {
    sc.simulation.seed = 500 + static_cast<unsigned>(s);
    auto [p, r] = test_support::quiet_run(sc);
    ASSERT_TRUE(r.converged());
    ASSERT_FALSE(r.modes.empty());
    const ModalEstimate& m = r.modes[0];
    ASSERT_TRUE(std::isfinite(m.frequency_std_hz)) << m.note;
    f.push_back(m.frequency_hz);
    if (s == 0) {
      std0 = m.frequency_std_hz;
      const MatrixXd R = correlation(r.ident);
      for (int i = 0; i < R.rows(); ++i) {
        EXPECT_NEAR(R(i, i), 1.0, 1e-12);
        for (int j = 0; j < R.cols(); ++j) {
          EXPECT_NEAR(R(i, j), R(j, i), 1e-12);
          EXPECT_LE(std::abs(R(i, j)), 1.0 + 1e-12);
        }
      }
      const auto j = r.to_json(*p);
      ASSERT_TRUE(j.contains("modes"));
      EXPECT_DOUBLE_EQ(j["modes"][0]["frequency_hz"].get<double>(), m.frequency_hz);
      EXPECT_EQ(j["identifiability"]["correlation"]["matrix"].size(), r.names.size());
    }
    covered += std::abs(m.frequency_hz - f1_true) <= m.frequency_half_width_hz;
  }
  double mean = 0, var = 0;
  for (double x : f) mean += x / seeds;
  for (double x : f) var += (x - mean) * (x - mean) / (seeds - 1);
  const double sd = std::sqrt(var);
  std::printf("  f1: truth %.7f Hz, mean %.7f, empirical std %.3e, propagated %.3e (ratio %.2f); intervals covering %d of %d\n",
              f1_true, mean, sd, std0, sd / std0, covered, seeds);
  EXPECT_GT(sd / std0, 0.7);  // 32 seeds: the sample std within ~±25 % at 2 sigma
  EXPECT_LT(sd / std0, 1.4);
  EXPECT_GE(covered, seeds - 3);
}
