// Checkpointing (time/checkpoints.h; docs/theory.md §7.9): a run resumed from any recorded
// resumable point reproduces the original points bit for bit (breakpoints included); windows share
// their boundaries and keep a breakpoint's two limits together; the gradient and the Gauss–Newton
// product on a checkpointed state equal the ones on the stored state to rounding, for several
// spacings, with each state segment re-solved once (with velocity and acceleration sensors too); streamed samples equal the stored solution's
// interpolant bit for bit (on breakpoints and beyond the run too) whatever the window.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "scoleid/identify/run/identify_run.h"
#include "scoleid/identify/time/checkpoints.h"

using namespace scoleid::identify;

namespace {
// beam-ei8 (EI on 8 sections, a step load and a haversine: breakpoints) on 16 elements, 2 s.
std::unique_ptr<Problem> ei8() {
  auto sc = scoleid::io::load_scenario("beam-ei8");
  sc.identification.elements = 16;
  sc.simulation.duration = 2.0;
  return make_problem(sc, std::nullopt);
}

struct Recorded {
  std::vector<double> t, x, v, a;
  std::vector<char> resumable;
  std::vector<double> origin, h;
};

Recorded record_all(const SecondOrderSolver& solver, int n, double t0, double t1, const SecondOrderSolver::Forcing& f,
                    const std::vector<double>& bps, const SecondOrderSolver::Start* start = nullptr,
                    double until = std::numeric_limits<double>::infinity()) {
  Recorded r;
  solver.stream(t0, t1, f, bps,
                [&](const SecondOrderSolver::Point& pt) {
                  r.t.push_back(pt.t);
                  r.x.insert(r.x.end(), pt.x, pt.x + n);
                  r.v.insert(r.v.end(), pt.v, pt.v + n);
                  r.a.insert(r.a.end(), pt.a, pt.a + n);
                  r.resumable.push_back(pt.resumable);
                  r.origin.push_back(pt.origin);
                  r.h.push_back(pt.h);
                },
                nullptr, start, until);
  return r;
}
}  // namespace

TEST(Checkpoints, ResumedRunReproducesTheOriginalPointsBitForBit) {
  const auto p = ei8();
  Objective o(p->model(), *p->params, p->signals, p->data, p->objective_options);
  const auto& M = p->model();
  const VectorXd q = p->params->initial();
  VectorXd c;
  MatrixXd dc;
  p->params->coefficients(q, c, dc);
  const AssembledModel ops = assemble(M, c);
  SolverOptions so = p->objective_options.solver;
  SecondOrderSolver solver(ops.M, ops.D, ops.K, M.dof_group, so);
  const int n = M.ndof;
  SecondOrderSolver::Forcing f = [&](double t, double* F) {
    Eigen::Map<VectorXd> Fm(F, n);
    for (std::size_t i = 0; i < ops.loads.size(); ++i) Fm += p->signals[i](t) * ops.loads[i];
  };
  std::vector<double> bps;
  for (const auto& s : p->signals)
    for (double b : s.breakpoints()) bps.push_back(b);
  const double T = p->data.t.back();
  const Recorded all = record_all(solver, n, 0.0, T, f, bps);
  // The stored solve records the same points as the stream.
  const Trajectory u = solver.solve(0.0, T, f, bps);
  ASSERT_EQ(u.size(), all.t.size());
  int breaks = 0;
  for (std::size_t k = 0; k + 1 < all.t.size(); ++k) breaks += all.t[k] == all.t[k + 1];
  ASSERT_GE(breaks, 2) << "the scenario should have breakpoints inside the record";
  // Resume from every 37th resumable point and from the right limit of each breakpoint, up to a
  // point 50 further on: the same bits.
  int resumed = 0, at_breaks = 0;
  for (std::size_t k = 0; k + 1 < all.t.size(); ++k) {
    const bool right_limit = k > 0 && all.t[k - 1] == all.t[k];
    if (!all.resumable[k] || !(k % 37 == 0 || right_limit)) continue;
    const std::size_t end = std::min(all.t.size() - 1, k + 50);
    const SecondOrderSolver::Start st{all.t[k], all.origin[k], all.h[k], &all.x[k * n], &all.v[k * n], &all.a[k * n]};
    const Recorded r = record_all(solver, n, 0.0, T, f, bps, &st, all.t[end]);
    // Ends at the first resumable point at or beyond `until`: the original's right limit if it is one.
    std::size_t last = end;
    while (last + 1 < all.t.size() && all.t[last + 1] == all.t[last]) ++last;
    ASSERT_EQ(r.t.size(), last - k + 1) << "from t = " << all.t[k];
    for (std::size_t j = 0; j < r.t.size(); ++j) {
      ASSERT_EQ(r.t[j], all.t[k + j]);
      for (int i = 0; i < n; ++i) {
        ASSERT_EQ(r.x[j * n + i], all.x[(k + j) * n + i]) << "t = " << r.t[j];
        ASSERT_EQ(r.v[j * n + i], all.v[(k + j) * n + i]);
        ASSERT_EQ(r.a[j * n + i], all.a[(k + j) * n + i]);
      }
    }
    ++resumed;
    at_breaks += right_limit;
  }
  std::printf("%zu points, %d breakpoint pairs; %d resumed runs (%d from a breakpoint) reproduce them bit for bit\n",
              all.t.size(), breaks, resumed, at_breaks);
  EXPECT_GE(at_breaks, 2);
}

TEST(Checkpoints, WindowsShareBoundariesAndKeepBreakpointLimitsTogether) {
  const int n = 1;
  std::vector<std::vector<double>> windows;
  WindowedSink sink(n, 3, [&](const Trajectory& w) { windows.push_back(w.times()); });
  const std::vector<double> ts{0, 1, 2, 3, 3, 4, 5, 6, 6, 7};
  double x = 0;
  for (double t : ts) {
    SecondOrderSolver::Point pt;
    pt.t = t;
    pt.x = pt.v = pt.a = &x;
    sink(pt);
  }
  sink.finish();
  std::vector<double> joined;
  for (std::size_t w = 0; w < windows.size(); ++w) {
    EXPECT_GE(windows[w].size(), 2u);
    if (w > 0) {
      EXPECT_EQ(windows[w].front(), windows[w - 1].back());  // shared boundary
      EXPECT_NE(windows[w][0], windows[w][1]) << "a breakpoint's limits split between windows";
    }
    joined.insert(joined.end(), windows[w].begin() + (w > 0 ? 1 : 0), windows[w].end());
  }
  EXPECT_EQ(joined, ts);
}

TEST(Checkpoints, AWindowOfTwoColumnsStacksThemAndRefusesAPointWithOne) {
  const int n = 2;
  std::vector<Trajectory> windows;
  WindowedSink sink(n, 2, [&](const Trajectory& w) { windows.push_back(w); }, 2);
  std::vector<double> x(2 * n);
  for (int k = 0; k < 3; ++k) {
    for (int i = 0; i < 2 * n; ++i) x[static_cast<std::size_t>(i)] = 10.0 * k + i;  // column 0: 10k, 10k+1; column 1: 10k+2, 10k+3
    SecondOrderSolver::Point pt;
    pt.t = k;
    pt.columns = 2;
    pt.x = pt.v = pt.a = x.data();
    sink(pt);
  }
  sink.finish();
  ASSERT_EQ(windows.size(), 2u);
  ASSERT_EQ(windows[0].dim(), 2 * n);
  for (int i = 0; i < 2 * n; ++i) EXPECT_EQ(windows[1].x(1)[i], 20.0 + i);  // both columns, stacked
  SecondOrderSolver::Point one;
  one.t = 3;
  one.columns = 1;
  one.x = one.v = one.a = x.data();
  EXPECT_THROW(sink(one), std::logic_error);
}

TEST(Checkpoints, GradientAndProductOnACheckpointedStateEqualTheStoredOnes) {
  const auto p = ei8();
  const VectorXd q = p->params->initial() * 1.05;
  Objective whole(p->model(), *p->params, p->signals, p->data, p->objective_options);
  VectorXd g0;
  const double J0 = whole.cost_and_gradient(q, g0);
  EXPECT_EQ(whole.counters().checkpointed_passes, 0);
  std::mt19937_64 rng(3);
  std::normal_distribution<double> n01;
  VectorXd v(q.size());
  for (int i = 0; i < v.size(); ++i) v[i] = n01(rng) * q[i];
  const VectorXd Hv0 = whole.gauss_newton_product(q, v);
  const double points = static_cast<double>(p->data.t.back() / p->objective_options.solver.step);
  for (long L : {5L, 40L, 300L}) {
    ObjectiveOptions oo = p->objective_options;
    oo.checkpoint_points = L;
    Objective ck(p->model(), *p->params, p->signals, p->data, oo);
    VectorXd g;
    const double J = ck.cost_and_gradient(q, g);
    const long resolves = ck.counters().checkpoint_resolves;
    const VectorXd Hv = ck.gauss_newton_product(q, v);
    const double eJ = std::abs(J / J0 - 1.0), eg = (g - g0).norm() / g0.norm(), eH = (Hv - Hv0).norm() / Hv0.norm();
    std::printf("L = %4ld: J %.1e, gradient %.1e, product %.1e (relative to the stored state); %ld segments re-solved, "
                "%.0f points\n",
                L, eJ, eg, eH, resolves, points);
    EXPECT_EQ(ck.counters().checkpointed_passes, 2);
    EXPECT_LT(eJ, 1e-12);
    EXPECT_LT(eg, 1e-10);
    EXPECT_LT(eH, 1e-10);
    // Each segment between checkpoints re-solved once as the backward pass moves through it.
    const double segments = std::ceil(points / static_cast<double>(L));
    EXPECT_LE(resolves, segments + 3);
    EXPECT_GE(resolves, segments - 3);
  }
}

TEST(Checkpoints, RateSensorGradientOnACheckpointedStateEqualsTheStoredOne) {
  // Velocity and acceleration sensors (docs/theory.md §6.1a): two backward equations streamed
  // together, their sources from the recorded A₀u and A₁u̇; the step load and the haversine's ends
  // make the acceleration output jump inside the record.
  auto sc = scoleid::io::load_scenario("beam-ei8");
  sc.identification.elements = 16;
  sc.simulation.duration = 2.0;
  sc.sensors[1].kind = scoleid::io::SensorKind::Velocity;
  sc.sensors[1].unit = "m/s";
  sc.sensors[4].kind = scoleid::io::SensorKind::Acceleration;
  sc.sensors[4].unit = "m/s^2";
  const auto p = make_problem(sc, std::nullopt);
  const VectorXd q = p->params->initial() * 1.05;
  Objective whole(p->model(), *p->params, p->signals, p->data, p->objective_options);
  ASSERT_FALSE(whole.has_matrix_free_products()) << "the scenario should have rate sensors";
  VectorXd g0;
  const double J0 = whole.cost_and_gradient(q, g0);
  EXPECT_EQ(whole.counters().checkpointed_passes, 0);
  // (The stored rate-sensor gradient is checked against differences and CVODES in gradient_test.)
  ASSERT_GT(g0.norm(), 0.0);
  // The cost alone is summed window by window over a streamed state (256 points a window, about
  // six here): the windows' grids join into the whole run's, so it is the Gauss–Newton pass's J,
  // which integrates the same grid point by point.
  VectorXd ggn;
  MatrixXd H;
  const double Jgn = whole.gauss_newton(q, ggn, H);
  const double Jc = whole.cost(q);
  std::printf("rate sensors: streamed cost %.1e from the Gauss-Newton pass's\n", std::abs(Jc / Jgn - 1.0));
  EXPECT_LT(std::abs(Jc / Jgn - 1.0), 1e-12);
  const double points = static_cast<double>(p->data.t.back() / p->objective_options.solver.step);
  for (long L : {1L, 5L, 40L, 300L}) {
    ObjectiveOptions oo = p->objective_options;
    oo.checkpoint_points = L;
    Objective ck(p->model(), *p->params, p->signals, p->data, oo);
    VectorXd g;
    const double J = ck.cost_and_gradient(q, g);
    const double eJ = std::abs(J / J0 - 1.0), eg = (g - g0).norm() / g0.norm();
    std::printf("rate sensors, L = %4ld: J %.1e, gradient %.1e (relative to the stored state); %ld segments re-solved\n",
                L, eJ, eg, ck.counters().checkpoint_resolves);
    EXPECT_EQ(ck.counters().checkpointed_passes, 1);
    EXPECT_EQ(ck.counters().costate_solves, 2);
    EXPECT_LT(eJ, 1e-12);
    EXPECT_LT(eg, 1e-10);
    const double segments = std::ceil(points / static_cast<double>(L));
    EXPECT_LE(ck.counters().checkpoint_resolves, segments + 3 + (L == 1 ? segments : 0));
    EXPECT_GE(ck.counters().checkpoint_resolves, segments - 3);
  }
}

TEST(Checkpoints, AutomaticSpacingOnlyBeyondTheTrajectoryBudget) {
  const auto p = ei8();
  const VectorXd q = p->params->initial();
  ObjectiveOptions oo = p->objective_options;
  oo.trajectory_bytes = 1024.0;  // every state exceeds it
  Objective small(p->model(), *p->params, p->signals, p->data, oo);
  VectorXd g;
  small.cost_and_gradient(q, g);
  EXPECT_EQ(small.counters().checkpointed_passes, 1);
  // √(points/3) segments' worth of points per checkpoint: about √(3 · points) re-solves.
  const double points = p->data.t.back() / p->objective_options.solver.step;
  EXPECT_NEAR(static_cast<double>(small.counters().checkpoint_resolves), std::sqrt(3.0 * points), 0.2 * std::sqrt(3.0 * points));
  Objective big(p->model(), *p->params, p->signals, p->data, p->objective_options);
  big.cost_and_gradient(q, g);
  EXPECT_EQ(big.counters().checkpointed_passes, 0);
}

TEST(Checkpoints, StreamedSamplesEqualTheStoredSolutionsInterpolant) {
  const auto p = ei8();
  const auto& M = p->model();
  VectorXd c;
  MatrixXd dc;
  p->params->coefficients(p->params->initial(), c, dc);
  const AssembledModel ops = assemble(M, c);
  SecondOrderSolver solver(ops.M, ops.D, ops.K, M.dof_group, p->objective_options.solver);
  const int n = M.ndof;
  SecondOrderSolver::Forcing f = [&](double t, double* F) {
    Eigen::Map<VectorXd> Fm(F, n);
    for (std::size_t i = 0; i < ops.loads.size(); ++i) Fm += p->signals[i](t) * ops.loads[i];
  };
  std::vector<double> bps, times = p->data.t;
  for (const auto& s : p->signals)
    for (double b : s.breakpoints()) bps.push_back(b), times.push_back(b);  // samples on the breakpoints too
  times.push_back(p->data.t.back() + 1.0);  // beyond the run: clamped
  std::sort(times.begin(), times.end());
  const double T = p->data.t.back();
  const Trajectory u = solver.solve(0.0, T, f, bps);
  VectorXd x(n), v(n);
  for (std::size_t window : {2u, 3u, 256u}) {
    std::size_t seen = 0;
    double worst = 0.0;
    sample_streamed(solver, 0.0, T, f, bps, times, [&](std::size_t k, const VectorXd& xs, const VectorXd& vs) {
      ASSERT_EQ(k, seen++);
      u.eval(times[k], x.data(), v.data());
      worst = std::max({worst, (xs - x).cwiseAbs().maxCoeff(), (vs - v).cwiseAbs().maxCoeff()});
    }, nullptr, window);
    EXPECT_EQ(seen, times.size());
    EXPECT_EQ(worst, 0.0) << "window " << window;
  }
}

TEST(Checkpoints, OnePointSpacingWhereWindowsSpanSeveralSegments) {
  // L = 1: a costate window (at least 2 points) and the state's one-step segments have no slack,
  // and T − (T − t) differs from t by an ulp, so a window can meet three segments (h = 1 ms here).
  const auto p = ei8();
  ObjectiveOptions base = p->objective_options;
  base.solver.step = 0.001;
  const VectorXd q = p->params->initial() * 0.97;
  Objective whole(p->model(), *p->params, p->signals, p->data, base);
  VectorXd g0, g;
  const double J0 = whole.cost_and_gradient(q, g0);
  VectorXd v = VectorXd::Ones(q.size());
  const VectorXd Hv0 = whole.gauss_newton_product(q, v);
  for (long L : {1L, 2L}) {
    ObjectiveOptions oo = base;
    oo.checkpoint_points = L;
    Objective ck(p->model(), *p->params, p->signals, p->data, oo);
    const double J = ck.cost_and_gradient(q, g);
    const VectorXd Hv = ck.gauss_newton_product(q, v);
    EXPECT_LT(std::abs(J / J0 - 1.0), 1e-12) << "L = " << L;
    EXPECT_LT((g - g0).norm(), 1e-10 * g0.norm()) << "L = " << L;
    EXPECT_LT((Hv - Hv0).norm(), 1e-10 * Hv0.norm()) << "L = " << L;
  }
}
