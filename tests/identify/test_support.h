#pragma once
// Helpers shared by the identifier tests: the Taylor remainder sequence of a gradient, and
// relative errors of estimates against a problem's true values.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <random>
#include <vector>

#include "scoleid/identify/inverse/cvodes_adjoint.h"
#include "scoleid/identify/run/identify_run.h"
#include "scoleid/io/error.h"

namespace scoleid::identify::test_support {

// R(ε_k) = |J(q ∘ exp(ε_k d)) − J(q) − ε_k ∇J·(q ∘ d)|, ε_k = 0.04/2^k, k = 0..5, for a random unit
// direction d in log q (seeded). A consistent gradient gives ratios R_k/R_{k+1} → 4.
inline std::vector<double> taylor_remainders(Objective& obj, const VectorXd& q, unsigned seed) {
  VectorXd g;
  const double J0 = obj.cost_and_gradient(q, g);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> N(0.0, 1.0);
  VectorXd d(q.size());
  for (int i = 0; i < q.size(); ++i) d[i] = N(rng);
  d /= d.norm();
  const double slope = g.dot(q.cwiseProduct(d));
  std::vector<double> R;
  std::printf("  %12s %14s %8s\n", "eps", "remainder", "ratio");
  for (int k = 0; k < 6; ++k) {
    const double eps = 0.04 / std::pow(2.0, k);
    const VectorXd qe = q.array() * (eps * d.array()).exp();
    R.push_back(std::abs(obj.cost(qe) - J0 - eps * slope));
    std::printf("  %12.4e %14.6e %8.3f\n", eps, R.back(), k ? R[static_cast<std::size_t>(k) - 1] / R.back() : 0.0);
  }
  return R;
}

// Second order: successive remainders R[k-1]/R[k] of taylor_remainders within (3.5, 4.5) for k in
// [first, last) (first order would give 2).
inline void expect_second_order(const std::vector<double>& R, std::size_t first = 1, std::size_t last = 0) {
  if (last == 0) last = R.size();
  for (std::size_t k = first; k < last; ++k) {
    EXPECT_GT(R[k - 1] / R[k], 3.5) << "halving " << k;
    EXPECT_LT(R[k - 1] / R[k], 4.5) << "halving " << k;
  }
}

// ∂J/∂q_i by central differences in log q_i with one Richardson step:
// D(η) = (J(q_i e^η) − J(q_i e^−η)) / (2η q_i),  ∂J/∂q_i ≈ (4 D(η/2) − D(η)) / 3  (error O(η⁴)).
inline VectorXd richardson_gradient(Objective& obj, const VectorXd& q, double eta = 1e-2) {
  VectorXd g(q.size());
  for (int i = 0; i < q.size(); ++i) {
    auto D = [&](double e) {
      VectorXd qp = q, qm = q;
      qp[i] *= std::exp(e);
      qm[i] *= std::exp(-e);
      return (obj.cost(qp) - obj.cost(qm)) / (2.0 * e * q[i]);
    };
    g[i] = (4.0 * D(0.5 * eta) - D(eta)) / 3.0;
  }
  return g;
}

// A problem and its objective built from scenario YAML text. `bdf` switches to CVODES BDF at
// rtol 1e-10 (the adaptive reference); `step` > 0 fixes the ESDIRK step.
struct Case {
  std::unique_ptr<Problem> p;
  std::unique_ptr<Objective> obj;
};

inline Case make_case(const std::string& yaml, bool bdf, double step = 0.0) {
  Case c;
  auto sc = scoleid::io::parse_scenario(yaml, "test");
  sc.identification.time_step = step;
  if (bdf) {
    sc.identification.integrator = scoleid::io::Integrator::Bdf;
    sc.identification.rtol = 1e-10;
  }
  c.p = make_problem(sc, std::nullopt);
  c.obj = std::make_unique<Objective>(c.p->model(), *c.p->params, c.p->signals, c.p->data, c.p->objective_options);
  return c;
}

// max_i |a_i − b_i| / |b_i|
inline double max_rel(const VectorXd& a, const VectorXd& b) {
  return ((a - b).cwiseAbs().array() / b.cwiseAbs().array().max(1e-300)).maxCoeff();
}

// Largest |q_i / truth_i − 1| over the estimated parameters.
inline double max_rel_error(const Problem& p, const VectorXd& q) {
  double e = 0.0;
  for (int i = 0; i < q.size(); ++i)
    e = std::max(e, std::abs(q[i] / p.true_values.at(p.params->names()[static_cast<std::size_t>(i)]) - 1.0));
  return e;
}

// First iteration whose every parameter is within `tol` of the truth (−1 if none).
inline int first_within(const Problem& p, const RunResult& r, double tol) {
  for (const auto& it : r.summary.iterations)
    if (max_rel_error(p, it.q) <= tol) return it.k;
  return -1;
}

// The costate gradient and the Gauss–Newton (forward-sensitivity) gradient at q against central
// differences of the cost (ESDIRK, fixed step): both agree to 1e-4 relative. Returns the differences.
inline VectorXd expect_gradients_match_differences(Objective& obj, const VectorXd& q) {
  VectorXd g_adj, g_gn;
  MatrixXd H;
  const double J_adj = obj.cost_and_gradient(q, g_adj);
  obj.gauss_newton(q, g_gn, H);
  const VectorXd g_fd = obj.finite_difference_gradient(q, 1e-5);
  std::printf("  esdirk: adjoint vs FD %.2e, Gauss-Newton vs FD %.2e\n", max_rel(g_adj, g_fd), max_rel(g_gn, g_fd));
  // The J a gradient returns is the cost's (a line search compares the two), whatever rule its
  // coefficient integrand takes.
  const double J = obj.cost(q);
  EXPECT_NEAR(J_adj, J, 1e-12 * J);
  EXPECT_LT(max_rel(g_adj, g_fd), 1e-4);
  EXPECT_LT(max_rel(g_gn, g_fd), 1e-4);
  return g_fd;
}

// A quiet run of the identifier on `sc` and its own synthetic data; the problem kept for its truth.
struct QuietRun {
  std::unique_ptr<Problem> p;
  RunResult r;
};
inline QuietRun quiet_run(const io::Scenario& sc, bool compute_std = true) {
  QuietRun q{make_problem(sc, std::nullopt), {}};
  RunOptions ro;
  ro.verbose = false;
  ro.compute_std = compute_std;
  q.r = run_identification(*q.p, ro);
  return q;
}

// The message of the io::InputError that running the identifier on `sc` throws (the problem is
// built first, outside the check); "" if the run goes through.
inline std::string run_error(const io::Scenario& sc) {
  auto p = make_problem(sc, std::nullopt);
  RunOptions ro;
  ro.verbose = false;
  try {
    run_identification(*p, ro);
  } catch (const io::InputError& e) {
    return e.what();
  }
  return "";
}

// Adaptive BDF at rtol 1e-10: the costate gradient of `yaml` at q against the CVODES adjoint
// (CVodeF/CVodeB), to 1e-5 in the gradient and 1e-6 in J; `fd`, if given, printed beside them.
inline void expect_costate_matches_cvodes(const std::string& yaml, const VectorXd& q, const VectorXd& fd = VectorXd()) {
  Case b = make_case(yaml, true);
  VectorXd g_b;
  const double Jb = b.obj->cost_and_gradient(q, g_b);
  const CvodesAdjointResult ref = cvodes_adjoint_gradient(*b.obj, q, 1e-10);
  std::printf("  bdf: costate vs CVODES adjoint %.2e (J %.10e vs %.10e)\n", max_rel(g_b, ref.gradient), Jb, ref.cost);
  for (int i = 0; i < q.size(); ++i) {
    std::printf("    %-9s costate %+.10e  cvodes %+.10e", b.p->params->names()[static_cast<std::size_t>(i)].c_str(), g_b[i],
                ref.gradient[i]);
    if (fd.size() == q.size()) std::printf("  fd(esdirk) %+.10e", fd[i]);
    std::printf("\n");
  }
  EXPECT_LT(max_rel(g_b, ref.gradient), 1e-5);
  EXPECT_NEAR(Jb, ref.cost, 1e-6 * ref.cost);
}

}  // namespace scoleid::identify::test_support
