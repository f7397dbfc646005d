// The structure-exploiting ESDIRK stepper (esdirk_stepper.h): it reproduces ARKODE's ARKStep on
// the same Butcher table, and the tangents it steps with the state are the derivatives of the
// discrete state, so the Gauss–Newton gradient is the gradient of the discrete cost.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "scoleid/identify/run/identify_run.h"
#include "test_support.h"

using namespace scoleid::identify;
using test_support::max_rel;

namespace {

// paper-scole-2 on a 2 s record (the pulses and the start of the free response), identifier at
// the paper's starting values.
std::unique_ptr<Problem> scole_problem(const std::string& integrator) {
  auto sc = scoleid::io::load_scenario("paper-scole-2");
  sc.simulation.duration = 2.0;
  sc.identification.integrator = *scoleid::io::parse<scoleid::io::Integrator>(integrator);
  return make_problem(sc, std::nullopt);
}

double max_abs(const MatrixXd& A) { return A.cwiseAbs().maxCoeff(); }

}  // namespace

TEST(EsdirkStepper, ReproducesArkodeOnTheSameTable) {
  auto a = scole_problem("esdirk"), b = scole_problem("esdirk-arkode");
  const VectorXd q = a->params->initial();
  Objective oa(a->model(), *a->params, a->signals, a->data, a->objective_options);
  Objective ob(b->model(), *b->params, b->signals, b->data, b->objective_options);
  const auto t0 = std::chrono::steady_clock::now();
  const MatrixXd Ya = oa.predict(q);
  const auto t1 = std::chrono::steady_clock::now();
  const MatrixXd Yb = ob.predict(q);
  const auto t2 = std::chrono::steady_clock::now();
  const double d = max_abs(Ya - Yb) / max_abs(Yb);
  std::printf("  max |stepper - ARKODE| / max |y| = %.2e; %.4f s vs %.4f s\n", d,
              std::chrono::duration<double>(t1 - t0).count(), std::chrono::duration<double>(t2 - t1).count());
  // Same stages, exact linear solves on both sides: rounding only.
  EXPECT_LT(d, 1e-11);
}

TEST(EsdirkStepper, TangentsAreTheDerivativesOfTheDiscreteState) {
  // Reference: Richardson-extrapolated central differences of the discrete outputs in log q,
  // D = (4 D(h/2) − D(h)) / 3, truncation O(h⁴). The step moves the outputs by ~1e-3 of their
  // peak (at most h = 0.005): the outputs are differences of absolute coordinates carrying the
  // rigid drift, so rounding is ~1e-12 of the peak. The cap is for the weakly seen ρI_ψ (which also
  // scales the section's bending rotary inertia): its reference's error is 4.9e-5 at h = 0.1,
  // 3.1e-6 at 0.02, 9.7e-8 at 0.005.
  auto p = scole_problem("esdirk");
  const VectorXd q = p->params->initial();
  Objective obj(p->model(), *p->params, p->signals, p->data, p->objective_options);
  const MatrixXd G = obj.output_sensitivities(q);  // tangents stepped with the state
  const int ns = p->data.sensors();
  auto central = [&](int i, double h) {
    VectorXd qp = q, qm = q;
    qp[i] *= std::exp(h);
    qm[i] *= std::exp(-h);
    return MatrixXd((obj.predict(qp) - obj.predict(qm)) / (2.0 * h));  // ∂y/∂ln q_i
  };
  const double peak = max_abs(obj.predict(q));
  for (int i = 0; i < q.size(); ++i) {
    MatrixXd Gi(G.rows() / ns, ns);
    for (Eigen::Index k = 0; k < Gi.rows(); ++k) Gi.row(k) = q[i] * G.block(k * ns, i, ns, 1).transpose();
    const double h = std::min(0.005, 1e-3 * peak / max_abs(Gi));
    const MatrixXd D = (4.0 * central(i, h / 2) - central(i, h)) / 3.0;
    const double e = max_abs(Gi - D) / max_abs(D);
    std::printf("  %-10s h %.1e: max |tangent - extrapolated difference| / max = %.2e\n",
                p->params->names()[static_cast<std::size_t>(i)].c_str(), h, e);
    EXPECT_LT(e, 1e-6) << p->params->names()[static_cast<std::size_t>(i)];
  }
}

TEST(EsdirkStepper, GaussNewtonGradientIsTheGradientOfTheDiscreteCost) {
  // Tangents on the state's own stages: the Gauss–Newton g = ∫ (CS)ᵀ R r dt is ∂J/∂q of the
  // discrete J (reference as above, per component). Integrating each sensitivity on its own with
  // the state interpolated (the ARKODE path) is a consistent approximation only.
  for (const char* integrator : {"esdirk", "esdirk-arkode"}) {
    auto p = scole_problem(integrator);
    const VectorXd q = p->params->initial();
    Objective obj(p->model(), *p->params, p->signals, p->data, p->objective_options);
    VectorXd g;
    MatrixXd H;
    obj.gauss_newton(q, g, H);
    // Steps as above, from the outputs' sensitivities (J is quadratic in the outputs).
    const MatrixXd G = obj.output_sensitivities(q);
    const double peak = max_abs(obj.predict(q));
    double e = 0.0;
    for (int i = 0; i < q.size(); ++i) {
      const double h = std::min(0.005, 1e-3 * peak / (q[i] * G.col(i).cwiseAbs().maxCoeff()));
      auto central = [&](double h) {
        VectorXd qp = q, qm = q;
        qp[i] *= std::exp(h);
        qm[i] *= std::exp(-h);
        return (obj.cost(qp) - obj.cost(qm)) / (2.0 * h);
      };
      const double d = (4.0 * central(h / 2) - central(h)) / 3.0;
      e = std::max(e, std::abs(q[i] * g[i] - d) / std::abs(d));
      std::printf("    %-10s h %.1e  g_GN %+.10e  g_FD %+.10e\n", p->params->names()[static_cast<std::size_t>(i)].c_str(), h, q[i] * g[i], d);
    }
    std::printf("  %-14s max relative |g_GN - g_FD| = %.2e\n", integrator, e);
    if (std::string(integrator) == "esdirk") {
      EXPECT_LT(e, 5e-6);
    }
  }
}

TEST(EsdirkStepper, AWholeRecordGaussNewtonSweepKeepsTheOutputSensitivitiesAtItsPoint) {
  // The Fisher step at the optimiser's last point costs no solve: the sweep that evaluated it
  // interpolated the output sensitivities at the samples on the way. Asked at that q they are the
  // numbers a sweep of their own gives (the same interpolation), without a solve; at another q,
  // or after a sweep on a shorter horizon, they are solved for.
  auto p = scole_problem("esdirk");
  const VectorXd q = p->params->initial();
  Objective swept(p->model(), *p->params, p->signals, p->data, p->objective_options);
  Objective fresh(p->model(), *p->params, p->signals, p->data, p->objective_options);
  VectorXd g;
  MatrixXd H;
  swept.gauss_newton(q, g, H);
  const long solves = swept.counters().sensitivity_solves;
  const MatrixXd Gk = swept.output_sensitivities(q);
  EXPECT_EQ(swept.counters().sensitivity_solves, solves);
  const MatrixXd Gf = fresh.output_sensitivities(q);
  EXPECT_EQ(fresh.counters().sensitivity_solves, q.size());
  ASSERT_EQ(Gk.rows(), Gf.rows());
  ASSERT_EQ(Gk.cols(), Gf.cols());
  EXPECT_EQ(max_abs(Gk - Gf), 0.0);
  EXPECT_GT(max_abs(Gf), 0.0);
  // Another point: solved, and different.
  VectorXd q2 = q;
  q2[0] *= 1.01;
  const MatrixXd G2 = swept.output_sensitivities(q2);
  EXPECT_EQ(swept.counters().sensitivity_solves, solves + q.size());
  EXPECT_GT(max_abs(G2 - Gk), 0.0);
  // A sweep on half the record keeps nothing: the next request at its q is solved.
  swept.set_horizon(0.5 * (swept.data_start() + swept.data_end()));
  swept.gauss_newton(q, g, H);
  const long after_half = swept.counters().sensitivity_solves;
  swept.set_horizon(swept.data_end());
  EXPECT_EQ(max_abs(swept.output_sensitivities(q) - Gf), 0.0);
  EXPECT_EQ(swept.counters().sensitivity_solves, after_half + q.size());
}

TEST(EsdirkStepper, ASweepSplitOverTwoThreadsGivesTheSameNumbersAsOne) {
  // The tangents in two groups, each stepped with its own copy of the state: a column's stages do
  // not depend on the others, so J, g, H, the misfit profile and the output sensitivities are the
  // one-thread sweep's bit for bit — on the whole record, and on a shorter horizon with the state
  // carried on to the record's end for the profile.
  auto p = scole_problem("esdirk");
  const VectorXd q = p->params->initial();
  ObjectiveOptions one = p->objective_options, two = p->objective_options;
  one.sweep_threads = 1;
  two.sweep_threads = 2;
  Objective a(p->model(), *p->params, p->signals, p->data, one), b(p->model(), *p->params, p->signals, p->data, two);
  for (double horizon : {a.data_end(), a.data_start() + 0.4 * (a.data_end() - a.data_start())}) {
    a.set_horizon(horizon);
    b.set_horizon(horizon);
    VectorXd ga, gb;
    MatrixXd Ha, Hb;
    Objective::MisfitProfile pa, pb;
    const double Ja = a.gauss_newton(q, ga, Ha, &pa), Jb = b.gauss_newton(q, gb, Hb, &pb);
    std::printf("  horizon %.2f s: J %.12e, |g| %.6e\n", horizon, Ja, ga.norm());
    EXPECT_GT(Ja, 0.0);
    EXPECT_EQ(Ja, Jb);
    EXPECT_EQ(max_abs(ga - gb), 0.0);
    EXPECT_EQ(max_abs(Ha - Hb), 0.0);
    EXPECT_EQ(pa.t, pb.t);
    EXPECT_EQ(pa.misfit, pb.misfit);
    EXPECT_FALSE(pa.t.empty());
  }
  a.set_horizon(a.data_end());
  b.set_horizon(b.data_end());
  VectorXd q2 = q;
  q2[1] *= 1.02;  // a point neither has kept
  EXPECT_EQ(max_abs(a.output_sensitivities(q2) - b.output_sensitivities(q2)), 0.0);
  // One grid stepped side by side: the steps are counted once, the solves of both.
  EXPECT_EQ(a.counters().solver.steps, b.counters().solver.steps);
  EXPECT_GT(b.counters().solver.linear_solves, a.counters().solver.linear_solves);
}

TEST(EsdirkStepper, AnEndAnchoredReversedRunStepsOnTheForwardGridMirrored) {
  // Two undamped oscillators (ω = 3, 7) under a unit step force from rest, x(t) = (1 − cos ωt)/ω²,
  // over [0, 2] with breakpoints 0.37 and 1.1 and h = 0.03 (which divides no segment). A run in
  // reversed time τ = 2 − t, anchored at its segments' ends, must step on the forward run's nodes
  // mirrored (the costates' quadrature grid is then the state's); anchored at their starts it
  // does not. Either way the solution keeps the method's accuracy.
  const int n = 2;
  const std::vector<double> w2 = {9.0, 49.0};
  SparseMatrix M(n, n), D(n, n), K(n, n);
  for (int i = 0; i < n; ++i) {
    M.insert(i, i) = 1.0;
    D.insert(i, i) = 0.0;
    K.insert(i, i) = w2[static_cast<std::size_t>(i)];
  }
  SolverOptions opt;
  opt.step = 0.03;
  const SecondOrderSolver solver(M, D, K, {0, 0}, opt);
  const double T = 2.0;
  const SecondOrderSolver::Forcing unit = [&](double, double* F) { F[0] = F[1] = 1.0; };
  const Trajectory fwd = solver.solve(0.0, T, unit, {0.37, 1.1});
  const std::vector<double> bp_tau = {T - 1.1, T - 0.37};
  const Trajectory end = solver.solve(0.0, T, unit, bp_tau, nullptr, StepAnchor::End);
  const Trajectory start = solver.solve(0.0, T, unit, bp_tau, nullptr, StepAnchor::Start);
  auto unmatched = [&](const Trajectory& rev) {
    int missing = 0;
    for (double tau : rev.times()) {
      const double t = T - tau;
      const auto it = std::lower_bound(fwd.times().begin(), fwd.times().end(), t - 1e-12);
      missing += !(it != fwd.times().end() && std::abs(*it - t) <= 1e-12);
    }
    return missing;
  };
  std::printf("  %zu forward nodes; reversed run's nodes off the mirrored grid: anchored at the end %d, at the start %d\n",
              fwd.size(), unmatched(end), unmatched(start));
  EXPECT_EQ(end.size(), fwd.size());
  EXPECT_EQ(unmatched(end), 0);
  EXPECT_GT(unmatched(start), 0);
  // Accuracy: the reversed runs solve the same problem (a constant force has no breakpoints of its
  // own), so both anchors meet the exact solution to the method's error.
  double e_end = 0.0, e_fwd = 0.0, peak = 0.0;
  VectorXd x(n), v(n);
  for (double t = 0.0; t <= T; t += 0.01) {
    for (int i = 0; i < n; ++i) peak = std::max(peak, 2.0 / w2[static_cast<std::size_t>(i)]);
    fwd.eval(t, x.data(), v.data());
    for (int i = 0; i < n; ++i) e_fwd = std::max(e_fwd, std::abs(x[i] - (1.0 - std::cos(std::sqrt(w2[i]) * t)) / w2[i]));
    end.eval(t, x.data(), v.data());
    for (int i = 0; i < n; ++i) e_end = std::max(e_end, std::abs(x[i] - (1.0 - std::cos(std::sqrt(w2[i]) * t)) / w2[i]));
  }
  std::printf("  max error / peak: start-anchored %.2e, end-anchored %.2e\n", e_fwd / peak, e_end / peak);
  EXPECT_LT(e_end / peak, 1e-3);
  EXPECT_LT(e_end, 3.0 * e_fwd);
}
