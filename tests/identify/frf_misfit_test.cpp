// The FRF misfit (identify/inverse/frf_misfit.h; docs/theory.md §6.10):
//   - the model's tip receptance of a clamped–free beam against the closed-form Euler–Bernoulli
//     value, converging as the mesh is refined;
//   - the adjoint gradient against extrapolated central differences and against the Jacobian's Jᵀr, with
//     accelerometers, damping and attachments (bench-cantilever), and a Taylor remainder of second order;
//   - recovery of EI, ρA and ζ from noisy FRFs synthesised on a finer mesh: χ²/N near 1 and every
//     estimate within four Fisher standard deviations of the truth.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <memory>
#include <random>

#include "scoleid/identify/fe/structure.h"
#include "scoleid/identify/inverse/frf_misfit.h"
#include "scoleid/identify/inverse/optimizers.h"
#include "scoleid/io/scenario.h"

using namespace scoleid::identify;
using Complex = std::complex<double>;

namespace {

constexpr double kTwoPi = 6.283185307179586476925286766559;

struct FeSetup {
  scoleid::io::Scenario sc;
  std::unique_ptr<FEStructure> st;
  std::unique_ptr<Parameterization> params;
};
FeSetup setup(scoleid::io::Scenario sc, int elements) {
  FeSetup s;
  s.sc = std::move(sc);
  s.st = make_structure(s.sc, elements);
  s.params = s.st->parameterize(s.sc);
  return s;
}

// A clamped–free steel strip with a force and a displacement sensor at the tip, undamped.
scoleid::io::Scenario cantilever() {
  return scoleid::io::parse_scenario(R"(
name: frf-cantilever
structure: beam
beam: {length: 0.5, left: clamped, right: free, rho_A: 0.58875, EI: 11.25, zeta: 0}
inputs: [{name: F, at: beam, kind: force, location: 0.5, signal: {type: step, amplitude: 1}}]
sensors: [{name: tip, at: beam, kind: displacement, location: 0.5}]
simulation: {duration: 1, sample_interval: 0.001}
identification: {estimate: [EI, rho_A]}
)",
                                     "frf-cantilever");
}

// Euler–Bernoulli tip receptance of a clamped–free beam under a tip force:
//   H = (cosh λ sin λ − sinh λ cos λ) / (EI β³ (1 + cosh λ cos λ)),  β⁴ = ρA ω²/EI, λ = βL
// (→ L³/3EI as ω → 0).
double cantilever_tip_receptance(double EI, double rhoA, double L, double w) {
  const double beta = std::pow(rhoA * w * w / EI, 0.25), l = beta * L;
  return (std::cosh(l) * std::sin(l) - std::sinh(l) * std::cos(l)) / (EI * beta * beta * beta * (1.0 + std::cosh(l) * std::cos(l)));
}

// The same at a complex frequency s (ω² = −s²: β⁴ = −ρA s²/EI; H is even in β under β → iβ and
// β → −β, so any fourth root serves).
Complex cantilever_tip_receptance(double EI, double rhoA, double L, Complex s) {
  const Complex beta = std::pow(-rhoA * s * s / EI, 0.25), l = beta * L;
  return (std::cosh(l) * std::sin(l) - std::sinh(l) * std::cos(l)) / (EI * beta * beta * beta * (1.0 + std::cosh(l) * std::cos(l)));
}

scoleid::io::FrfData lines_of(const std::vector<double>& f, int channels) {
  scoleid::io::FrfData d;
  d.source = "test";
  d.estimator = "file";
  d.f_hz = f;
  for (int s = 0; s < channels; ++s) {
    scoleid::io::FrfData::Channel ch;
    ch.sensor = "s" + std::to_string(s);
    ch.H.assign(f.size(), Complex(0.0, 0.0));
    ch.variance.assign(f.size(), 1.0);
    d.channels.push_back(ch);
  }
  return d;
}

std::vector<int> all_sensors(const StructuralModel& m) {
  std::vector<int> s;
  for (int i = 0; i < static_cast<int>(m.sensors.size()); ++i) s.push_back(i);
  return s;
}

}  // namespace

TEST(FrfMisfit, TipReceptanceMatchesEulerBernoulliAndConvergesWithTheMesh) {
  const std::vector<double> f = {3.0, 20.0, 35.0, 80.0, 150.0};  // the first three modes lie at 9.7, 61, 171 Hz
  double previous = 0.0;
  for (int elements : {4, 8, 16, 32}) {
    auto s = setup(cantilever(), elements);
    FrfMisfit m(s.st->model(), *s.params, lines_of(f, 1), {0}, 0, {1});
    const ComplexMatrix H = m.predict(s.params->truth());
    double worst = 0.0;
    for (std::size_t k = 0; k < f.size(); ++k) {
      const double exact = cantilever_tip_receptance(11.25, 0.58875, 0.5, kTwoPi * f[k]);
      EXPECT_NEAR(H(static_cast<Eigen::Index>(k), 0).imag(), 0.0, 1e-12 * std::abs(exact));  // undamped: real
      worst = std::max(worst, std::abs(H(static_cast<Eigen::Index>(k), 0).real() / exact - 1.0));
    }
    std::printf("elements %2d: worst relative error %.3e\n", elements, worst);
    if (previous > 0) { EXPECT_LT(worst, previous / 8.0) << "cubic Hermite elements: frequencies converge as h^4"; }
    previous = worst;
  }
  EXPECT_LT(previous, 1e-4);
}

// Under an exponential window (decay a) the data are H(a + iω): the model's tip receptance at that
// complex frequency matches Euler–Bernoulli's and converges with the mesh as at iω.
TEST(FrfMisfit, AtADecayTheTipReceptanceIsEulerBernoullisAtTheComplexFrequency) {
  const std::vector<double> f = {3.0, 9.0, 20.0, 61.0, 150.0};
  const double a = 4.0;
  double previous = 0.0;
  for (int elements : {4, 8, 16, 32}) {
    auto s = setup(cantilever(), elements);
    auto data = lines_of(f, 1);
    data.decay = a;
    FrfMisfit m(s.st->model(), *s.params, data, {0}, 0, {1});
    const ComplexMatrix H = m.predict(s.params->truth());
    double worst = 0.0;
    for (std::size_t k = 0; k < f.size(); ++k) {
      const Complex exact = cantilever_tip_receptance(11.25, 0.58875, 0.5, Complex(a, kTwoPi * f[k]));
      worst = std::max(worst, std::abs(H(static_cast<Eigen::Index>(k), 0) / exact - 1.0));
    }
    std::printf("elements %2d: worst relative error at s = %g + i omega %.3e\n", elements, a, worst);
    if (previous > 0) { EXPECT_LT(worst, previous / 8.0); }
    previous = worst;
  }
  EXPECT_LT(previous, 1e-4);
}

namespace {
// bench-cantilever's model (accelerometers, attachments, a compliant clamp, Chen–Russell damping),
// with measured FRFs made at q_data and noise-free, and the misfit at the scenario's parameters.
struct BenchMisfit {
  FeSetup s;
  std::unique_ptr<FrfMisfit> m;
};
BenchMisfit bench_misfit(const VectorXd& data_scale, double decay = 0.0) {
  BenchMisfit b;
  b.s = setup(scoleid::io::load_scenario("bench-cantilever"), 8);
  std::vector<double> f;
  for (double x = 2.0; x < 200.0; x *= 1.13) f.push_back(x);
  const auto model_sensors = all_sensors(b.s.st->model());
  auto d = lines_of(f, 2);
  d.decay = decay;
  FrfMisfit truth(b.s.st->model(), *b.s.params, d, model_sensors, 0, {1});
  const VectorXd qd = b.s.params->truth().cwiseProduct(data_scale);
  const ComplexMatrix H = truth.predict(qd);
  for (int s = 0; s < 2; ++s)
    for (std::size_t k = 0; k < f.size(); ++k) {
      d.channels[static_cast<std::size_t>(s)].H[k] = H(static_cast<Eigen::Index>(k), s);
      d.channels[static_cast<std::size_t>(s)].variance[k] = std::pow(0.01 * std::abs(H(static_cast<Eigen::Index>(k), s)), 2);
    }
  b.m = std::make_unique<FrfMisfit>(b.s.st->model(), *b.s.params, d, model_sensors, 0);
  return b;
}
}  // namespace

class FrfMisfitDecay : public ::testing::TestWithParam<double> {};

TEST_P(FrfMisfitDecay, AdjointGradientMatchesCentralDifferencesAndTheJacobian) {
  const int P = 5;
  VectorXd scale(P);
  scale << 1.07, 0.95, 1.2, 0.9, 1.1;  // data made off the point where the gradient is taken
  auto b = bench_misfit(scale, GetParam());  // without a window, and at s = a + iω
  ASSERT_EQ(b.s.params->size(), P);
  const VectorXd q = b.s.params->initial();
  VectorXd g, gj;
  b.m->cost_and_gradient(q, g);
  MatrixXd H;
  b.m->gauss_newton(q, gj, H);
  double worst = 0.0, worst_j = 0.0;
  for (int p = 0; p < P; ++p) {
    // Central differences at h and h/2, extrapolated (error O(h⁴)).
    auto central = [&](double h) {
      VectorXd qp = q, qm = q;
      qp[p] += h;
      qm[p] -= h;
      return (b.m->cost(qp) - b.m->cost(qm)) / (2.0 * h);
    };
    const double h = 1e-4 * q[p];
    const double fd = (4.0 * central(h / 2.0) - central(h)) / 3.0;
    worst = std::max(worst, std::abs(g[p] - fd) * q[p] / (std::abs(fd) * q[p] + 1e-300));
    worst_j = std::max(worst_j, std::abs(gj[p] - g[p]) / std::abs(g[p]));
    std::printf("%-28s adjoint %+.10e  fd %+.10e  Jacobian %+.10e\n", b.s.params->names()[static_cast<std::size_t>(p)].c_str(), g[p], fd, gj[p]);
  }
  EXPECT_LT(worst, 1e-5);  // measured 1.4e-6: the cost near a lightly damped peak is rough below that
  EXPECT_LT(worst_j, 1e-10);
}

INSTANTIATE_TEST_SUITE_P(FrfMisfit, FrfMisfitDecay, ::testing::Values(0.0, 6.0));

TEST(FrfMisfit, TaylorRemainderIsSecondOrder) {
  VectorXd scale(5);
  scale << 1.05, 0.97, 1.1, 0.95, 1.02;
  auto b = bench_misfit(scale);
  const VectorXd q = b.s.params->initial();
  VectorXd g;
  const double J0 = b.m->cost_and_gradient(q, g);
  VectorXd dir(5);
  dir << 0.3, -0.5, 0.7, 0.2, -0.4;
  dir = dir.cwiseProduct(q);
  double previous = 0.0;
  for (double e : {1e-2, 5e-3, 2.5e-3, 1.25e-3}) {
    const double rem = std::abs(b.m->cost(q + e * dir) - J0 - e * g.dot(dir));
    if (previous > 0) {
      const double ratio = previous / rem;
      std::printf("eps %.4g remainder %.4e ratio %.3f\n", e, rem, ratio);
      EXPECT_GT(ratio, 3.6);
      EXPECT_LT(ratio, 4.4);
    }
    previous = rem;
  }
}

TEST(FrfMisfit, RecoversEIRhoAAndZetaFromNoisyFrfsOfAFinerMesh) {
  auto sc = cantilever();
  sc.beam.zeta = 0.01;
  sc.identification.estimate = {"EI", "rho_A", "zeta"};
  sc.sensors[0].kind = scoleid::io::SensorKind::Acceleration;
  auto fine = setup(sc, 32);
  auto coarse = setup(sc, 12);
  std::vector<double> f;
  for (double x = 1.0; x <= 250.0; x += 0.5) f.push_back(x);
  FrfMisfit maker(fine.st->model(), *fine.params, lines_of(f, 1), {0}, 0);
  const ComplexMatrix H = maker.predict(fine.params->truth());
  auto d = lines_of(f, 1);
  std::mt19937 rng(7);
  std::normal_distribution<double> n01;
  for (std::size_t k = 0; k < f.size(); ++k) {
    const double sigma = 0.02 * std::abs(H(static_cast<Eigen::Index>(k), 0)) + 1e-3;  // relative plus a floor
    d.channels[0].variance[k] = sigma * sigma;
    d.channels[0].H[k] = H(static_cast<Eigen::Index>(k), 0) + Complex(n01(rng), n01(rng)) * (sigma / std::sqrt(2.0));
  }
  FrfMisfit m(coarse.st->model(), *coarse.params, d, {0}, 0);
  VectorXd q0 = coarse.params->truth();
  q0[0] *= 1.2;
  q0[1] *= 0.8;
  q0[2] *= 1.5;
  OptimizerOptions o;
  o.method = scoleid::io::Method::GaussNewton;
  const auto summary = minimize(m, q0, o);
  ASSERT_TRUE(summary.converged()) << summary.message;
  VectorXd r;
  MatrixXd Jac;
  const double J = m.residuals(summary.q, r, &Jac);
  const double chi2_per_value = 2.0 * J / static_cast<double>(m.data_points());
  std::printf("chi2/N %.4f after %d iterations\n", chi2_per_value, summary.iterations_done);
  EXPECT_NEAR(chi2_per_value, 1.0, 4.0 * std::sqrt(2.0 / static_cast<double>(m.data_points())) + 0.02);
  const MatrixXd C = (Jac.transpose() * Jac).inverse();
  const VectorXd truth = coarse.params->truth();
  for (int p = 0; p < 3; ++p) {
    const double sd = std::sqrt(C(p, p));
    std::printf("%-6s estimate %.6e truth %.6e (%+.3e), std %.2e\n", coarse.params->names()[static_cast<std::size_t>(p)].c_str(),
                summary.q[p], truth[p], summary.q[p] / truth[p] - 1.0, sd / truth[p]);
    EXPECT_LT(std::abs(summary.q[p] - truth[p]), 4.0 * sd + 2e-4 * truth[p]);
  }
}
