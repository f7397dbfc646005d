// Matrix-free Gauss–Newton products (objective.h, gauss_newton_product; docs/theory.md §7.7): H v
// from one tangent and one costate solve against the matrix of P sensitivity solves, symmetry
// ⟨w, H v⟩ = ⟨v, H w⟩, and Taylor tests on data the model reproduces at q (residual zero, so the
// Gauss–Newton matrix is the Hessian there): J(q + εv) − J − ε gᵀv falls as ε² and, with ½ε² vᵀHv
// taken off too, as ε³.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <tuple>

#include "scoleid/identify/inverse/optimizers.h"
#include "scoleid/identify/inverse/tied_parameterization.h"
#include "scoleid/identify/run/identify_run.h"

using namespace scoleid::identify;

namespace {
struct Case {
  std::unique_ptr<Problem> p;
  Measurements data;
};
// beam-ei8 (EI on 8 sections, displacement sensors) on 16 elements, 2 s; data the model's own
// output at the initial point when `reproduce`.
Case ei8(bool reproduce) {
  auto sc = scoleid::io::load_scenario("beam-ei8");
  sc.identification.elements = 16;
  sc.simulation.duration = 2.0;
  Case c{make_problem(sc, std::nullopt), {}};
  c.data = c.p->data;
  if (reproduce) {
    Objective o(c.p->model(), *c.p->params, c.p->signals, c.p->data, c.p->objective_options);
    c.data.z = o.predict(c.p->params->initial());
  }
  return c;
}
VectorXd random_direction(int P, unsigned seed, const VectorXd& scale) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n01;
  VectorXd v(P);
  for (int i = 0; i < P; ++i) v[i] = n01(rng) * scale[i];
  return v;
}
}  // namespace

TEST(MatrixFree, ProductMatchesTheSensitivityMatrixAndIsSymmetric) {
  const Case c = ei8(false);
  Objective o(c.p->model(), *c.p->params, c.p->signals, c.data, c.p->objective_options);
  ASSERT_TRUE(o.has_matrix_free_products());
  const VectorXd q = c.p->params->initial() * 1.05;
  VectorXd g;
  MatrixXd H;
  o.gauss_newton(q, g, H);
  const int P = o.size();
  double worst = 0.0;
  for (unsigned seed = 1; seed <= 3; ++seed) {
    const VectorXd v = random_direction(P, seed, q), w = random_direction(P, seed + 10, q);
    o.reset_counters();
    const VectorXd Hv = o.gauss_newton_product(q, v);
    // Two solves whatever P: the state with the one tangent, and one costate.
    EXPECT_EQ(o.counters().forward_solves, 1);
    EXPECT_EQ(o.counters().costate_solves, 1);
    EXPECT_EQ(o.counters().sensitivity_solves, 1);
    const VectorXd ref = H * v;
    const double rel = (Hv - ref).norm() / ref.norm();
    worst = std::max(worst, rel);
    const VectorXd Hw = o.gauss_newton_product(q, w);
    const double sym = std::abs(w.dot(Hv) - v.dot(Hw)) / std::abs(w.dot(ref));
    std::printf("direction %u: |Hv - H_sens v| / |H v| = %.2e, |<w,Hv> - <v,Hw>| / |<w,Hv>| = %.2e\n", seed, rel, sym);
    // The two are the same continuous quantity discretised differently (tangent then costate, both
    // on the solver's steps): they agree to the integrator's accuracy.
    EXPECT_LT(rel, 1e-4);
    EXPECT_LT(sym, 1e-4);
  }
}

TEST(MatrixFree, TaylorRemaindersFallAtSecondAndThirdOrder) {
  const Case c = ei8(true);
  Objective o(c.p->model(), *c.p->params, c.p->signals, c.data, c.p->objective_options);
  const VectorXd q = c.p->params->initial();
  const VectorXd v = random_direction(o.size(), 4, q);
  // The gradient about q1 = q + 0.02 v (residual, J and g nonzero): J(q1 + εv) − J − ε gᵀv = O(ε²).
  const VectorXd q1 = q + 0.02 * v;
  VectorXd g;
  const double J1 = o.cost_and_gradient(q1, g);
  // The product about q, where the data are the model's own output at the samples: the residual is
  // only the data's interpolation between samples (J(q) ~ 1e-8 of a relative mean square), so the
  // Gauss–Newton matrix is the Hessian there and J(q + εv) − J − ε gᵀv − ½ ε² vᵀHv = O(ε³).
  VectorXd g0;
  const double J0 = o.cost_and_gradient(q, g0);
  const VectorXd Hv = o.gauss_newton_product(q, v);
  EXPECT_LT(J0, 1e-7);
  double r2_prev = 0, r3_prev = 0;
  std::printf("   eps     gradient: J(q1+ev)-J-e g.v   product: J(q+ev)-e^2/2 v.Hv\n");
  for (int k = 0; k < 4; ++k) {
    const double eps = 0.02 / std::pow(2.0, k);
    const double r2 = std::abs(o.cost(q1 + eps * v) - J1 - eps * g.dot(v));
    const double r3 = std::abs(o.cost(q + eps * v) - J0 - eps * g0.dot(v) - 0.5 * eps * eps * v.dot(Hv));
    std::printf("%9.2e  %.4e                  %.4e\n", eps, r2, r3);
    if (k > 0) {
      EXPECT_NEAR(std::log2(r2_prev / r2), 2.0, 0.15) << "eps " << eps;
      EXPECT_NEAR(std::log2(r3_prev / r3), 3.0, 0.2) << "eps " << eps;
    }
    r2_prev = r2;
    r3_prev = r3;
  }
}

namespace {
// EI on 16 sections of a simply supported beam (a smooth profile), 4 displacement sensors, 1 % noise
// stated to the identifier: the sections between sensors are poorly seen.
scoleid::io::Scenario sections_scenario(const std::string& smoothness, int N, int sensors, double noise) {
  auto sc = scoleid::io::load_scenario("beam-ei8");
  sc.beam.EI.resize(N);
  for (int k = 0; k < N; ++k) {
    const double x = (k + 0.5) * sc.beam.length / N;
    sc.beam.EI[static_cast<std::size_t>(k)] =
        23000.0 * (1.0 + 0.3 * std::sin(M_PI * x / sc.beam.length) + 0.1 * std::cos(3.0 * M_PI * x / sc.beam.length));
  }
  const auto sensor = sc.sensors.front();
  sc.sensors.assign(static_cast<std::size_t>(sensors), sensor);
  for (int i = 0; i < sensors; ++i) {
    sc.sensors[static_cast<std::size_t>(i)].name = "w" + std::to_string(i + 1);
    sc.sensors[static_cast<std::size_t>(i)].location = (i + 0.5) * sc.beam.length / sensors;
  }
  sc.simulation.duration = 4.0;
  sc.simulation.seed = 3;
  sc.identification.estimate.clear();
  for (int k = 1; k <= N; ++k) sc.identification.estimate.push_back("EI_" + std::to_string(k));
  sc.identification.method = scoleid::io::Method::GaussNewtonKrylov;
  // Noise of `noise` times each sensor's RMS, from the noise-free data.
  const auto clean = make_problem(sc, std::nullopt);
  for (int i = 0; i < sensors; ++i)
    sc.sensors[static_cast<std::size_t>(i)].noise_std = noise * std::sqrt(clean->data.z.col(i).squaredNorm() / clean->data.z.rows());
  sc.identification.smoothness = smoothness == "discrepancy" ? -1.0 : std::stod(smoothness);
  return sc;
}
// EI on 16 sections, 4 sensors, 1 % noise.
scoleid::io::Scenario sixteen_sections(const std::string& smoothness) { return sections_scenario(smoothness, 16, 4, 0.01); }
double rms_error(const RunResult& r) {
  double s = 0;
  for (std::size_t i = 0; i < r.names.size(); ++i) s += std::pow(r.estimate[static_cast<Eigen::Index>(i)] / r.truth.at(r.names[i]) - 1.0, 2);
  return std::sqrt(s / static_cast<double>(r.names.size()));
}
}  // namespace

TEST(SmoothnessPrior, DiscrepancyWeightIsTheLargestWithinTheNoiseAndHalvesTheSectionsError) {
  RunOptions ro;
  ro.verbose = false;
  ro.compute_std = false;
  auto plain = make_problem(sixteen_sections("0"), std::nullopt);
  const RunResult a = run_identification(*plain, ro);
  auto smooth = make_problem(sixteen_sections("discrepancy"), std::nullopt);
  const RunResult b = run_identification(*smooth, ro);
  std::printf("16 sections, 4 sensors, 1 %% noise: RMS error %.3e without prior (%s), %.3e with the discrepancy weight %.1e "
              "(%zu weights tried; data misfit %.4e, noise band %.4e); %ld and %ld CG iterations\n",
              rms_error(a), to_string(a.summary.termination), rms_error(b), b.smoothness_weight, b.smoothness_path.size(),
              b.smoothness_path.back().data_misfit, b.smoothness_expected_misfit, a.summary.krylov_iterations,
              b.summary.krylov_iterations);
  EXPECT_TRUE(a.summary.converged());
  EXPECT_TRUE(b.converged());
  ASSERT_TRUE(b.smoothness_met);
  // Morozov: the chosen weight meets the noise band, the one ten times larger did not.
  ASSERT_GE(b.smoothness_path.size(), 2u);
  EXPECT_LE(b.smoothness_path.back().data_misfit, b.smoothness_expected_misfit);
  EXPECT_GT(b.smoothness_path[b.smoothness_path.size() - 2].data_misfit, b.smoothness_expected_misfit);
  // The prior takes the wandering out of the sections the sensors barely see (measured 9.3e-2 →
  // 4.9e-2 on this record).
  EXPECT_LT(rms_error(b), 0.7 * rms_error(a));
}

// The last Gauss–Newton evaluation is kept (objective.h): asked again at the same q on the same
// horizon (an optimiser run going on from where the previous one stopped) it is returned as it was,
// without a solve; another point, another horizon or a profile asked for are solved.
TEST(GaussNewton, TheLastEvaluationIsReturnedAgainOnlyForTheSamePointAndHorizon) {
  const Case c = ei8(false);
  Objective o(c.p->model(), *c.p->params, c.p->signals, c.data, c.p->objective_options);
  const VectorXd q = c.p->params->initial() * 1.05;
  VectorXd g1, g2, g3;
  MatrixXd H1, H2, H3;
  const double J1 = o.gauss_newton(q, g1, H1);
  o.reset_counters();
  const double J2 = o.gauss_newton(q, g2, H2);
  EXPECT_EQ(o.counters().forward_solves, 0);
  EXPECT_EQ(o.counters().sensitivity_solves, 0);
  EXPECT_EQ(J2, J1);
  EXPECT_TRUE(g2 == g1 && H2 == H1);
  // Another point: solved, and its numbers differ.
  VectorXd q2 = q;
  q2[0] *= 1.01;
  o.gauss_newton(q2, g3, H3);
  EXPECT_EQ(o.counters().forward_solves, 1);
  EXPECT_GT(o.counters().sensitivity_solves, 0);
  EXPECT_NE(g3[0], g1[0]);
  // Back at q: solved again (only the last evaluation is kept), the same numbers bit for bit.
  o.reset_counters();
  EXPECT_EQ(o.gauss_newton(q, g2, H2), J1);
  EXPECT_EQ(o.counters().forward_solves, 1);
  EXPECT_TRUE(g2 == g1 && H2 == H1);
  // A shorter horizon is another cost: solved; and the whole record's again after it.
  o.set_horizon(0.5 * (o.data_start() + o.data_end()));
  o.reset_counters();
  const double Jh = o.gauss_newton(q, g3, H3);
  EXPECT_EQ(o.counters().forward_solves, 1);
  EXPECT_NE(Jh, J1);
  o.set_horizon(o.data_end());
  o.reset_counters();
  EXPECT_EQ(o.gauss_newton(q, g2, H2), J1);
  EXPECT_EQ(o.counters().forward_solves, 1);
  // With a profile asked for: solved (the profile is not kept).
  Misfit::MisfitProfile prof;
  o.reset_counters();
  EXPECT_EQ(o.gauss_newton(q, g2, H2, &prof), J1);
  EXPECT_EQ(o.counters().forward_solves, 1);
  EXPECT_FALSE(prof.t.empty());
}

// The step matrix (objective.h, docs/theory.md §7.2): J and g are the costate's on the solver's
// step, bit for bit; H is that of the same objective on the coarsened step (its tangents' time
// error only), close to the fine matrix; kept like gauss_newton's; the same as gauss_newton where
// no coarser step applies.
TEST(GaussNewton, TheStepMatrixIsTheCoarserStepsWithTheModelsCostAndGradient) {
  const auto sc = sections_scenario("0", 24, 4, 0.01);
  const auto p = make_problem(sc, std::nullopt);
  const ObjectiveOptions fine_options = p->objective_options;
  ASSERT_GT(fine_options.solver.step, 0.0);
  Objective o(p->model(), *p->params, p->signals, p->data, fine_options);
  const double hm = o.step_matrix_step();
  EXPECT_GT(hm, fine_options.solver.step);
  EXPECT_LE(hm, fine_options.step_matrix_coarsening * fine_options.solver.step * (1.0 + 1e-12));
  const VectorXd q = p->params->initial() * 1.05;
  VectorXd g, g_ref, g_fine, g_coarse;
  MatrixXd H, H_fine, H_coarse;
  const double J = o.gradient_and_step_matrix(q, g, H);
  {
    Objective ref(p->model(), *p->params, p->signals, p->data, fine_options);
    EXPECT_EQ(ref.cost_and_gradient(q, g_ref), J);
    EXPECT_TRUE(g == g_ref);
    ref.gauss_newton(q, g_fine, H_fine);
  }
  ObjectiveOptions coarse_options = fine_options;
  coarse_options.solver.step = hm;
  Objective coarse(p->model(), *p->params, p->signals, p->data, coarse_options);
  coarse.gauss_newton(q, g_coarse, H_coarse);
  EXPECT_TRUE(H == H_coarse);
  const double dH = (H - H_fine).norm() / H_fine.norm();
  std::printf("step %.3g s, matrix step %.3g s: |H - H_fine| / |H_fine| = %.2e\n", fine_options.solver.step, hm, dH);
  EXPECT_GT(dH, 0.0);
  EXPECT_LT(dH, 1e-2);
  // Kept: the same point and horizon cost nothing.
  o.reset_counters();
  VectorXd g2;
  MatrixXd H2;
  EXPECT_EQ(o.gradient_and_step_matrix(q, g2, H2), J);
  EXPECT_EQ(o.counters().forward_solves + o.counters().sensitivity_solves + o.counters().costate_solves, 0);
  EXPECT_TRUE(g2 == g && H2 == H);
  // On a shorter horizon: solved there, both parts on that horizon.
  o.set_horizon(0.5 * (o.data_start() + o.data_end()));
  const double Jh = o.gradient_and_step_matrix(q, g2, H2);
  coarse.set_horizon(o.horizon());
  coarse.gauss_newton(q, g_coarse, H_coarse);
  EXPECT_LT(Jh, J);
  EXPECT_TRUE(H2 == H_coarse);
  // No coarsening: gauss_newton itself.
  ObjectiveOptions same = fine_options;
  same.step_matrix_coarsening = 1.0;
  Objective plain(p->model(), *p->params, p->signals, p->data, same);
  EXPECT_EQ(plain.step_matrix_step(), fine_options.solver.step);
  EXPECT_EQ(plain.gradient_and_step_matrix(q, g2, H2), plain.gauss_newton(q, g_fine, H_fine));
  EXPECT_TRUE(H2 == H_fine);
}

// A run with many parameters that ends on an accepted step (here a coarse stall threshold: a step
// gaining less than 1e-3 of J ends it) takes no matrix at that last point: the matrices counted are
// the start's and every earlier accepted point's. Its gradient came with the trial where the step
// matrix is an evaluation of its own (objective.h: the trial's cost and gradient by the costate);
// where it is not, the trial took the cost alone and the record's gradient norm is NaN. A run going
// on from there evaluates the point itself, the same numbers as a fresh objective's.
TEST(GaussNewton, ARunEndingOnAStepTakesNoMatrixThere) {
  const auto sc = sections_scenario("0", 24, 4, 0.01);
  const auto p = make_problem(sc, std::nullopt);
  for (const double coarsening : {kStepMatrixCoarsening, 1.0}) {
    ObjectiveOptions oo_obj = p->objective_options;
    oo_obj.step_matrix_coarsening = coarsening;
    Objective o(p->model(), *p->params, p->signals, p->data, oo_obj);
    ASSERT_EQ(o.has_separate_step_matrix(), coarsening > 1.0);
    OptimizerOptions oo;
    oo.method = scoleid::io::Method::GaussNewton;
    oo.continuation = false;
    oo.cost_stall = 1e-3;
    const OptimizerSummary s = minimize(o, p->params->initial() * 1.1, oo);
    std::printf("coarsening %g: %s; %ld tangent columns\n", coarsening, s.BriefReport().c_str(), o.counters().sensitivity_solves);
    ASSERT_EQ(s.termination, OptimizerSummary::Termination::CostStalled) << s.BriefReport();
    ASSERT_GE(s.iterations_done, 1);
    EXPECT_EQ(std::isnan(s.iterations.back().gradient_norm), !o.has_separate_step_matrix());
    for (std::size_t i = 0; i + 1 < s.iterations.size(); ++i) EXPECT_TRUE(std::isfinite(s.iterations[i].gradient_norm));
    EXPECT_EQ(o.counters().sensitivity_solves, 24L * s.iterations_done);
    // Going on from the last point: evaluated there, the same numbers as a fresh objective's.
    OptimizerOptions more = oo;
    more.max_iterations = 0;
    o.reset_counters();
    const OptimizerSummary t = minimize(o, s.q, more);
    EXPECT_EQ(o.counters().sensitivity_solves, 24L);
    Objective fresh(p->model(), *p->params, p->signals, p->data, oo_obj);
    VectorXd g;
    MatrixXd H;
    fresh.gradient_and_step_matrix(s.q, g, H);
    EXPECT_EQ(t.iterations.front().gradient_norm, s.q.cwiseProduct(g).cwiseAbs().maxCoeff());
    if (o.has_separate_step_matrix()) {
      EXPECT_EQ(s.iterations.back().gradient_norm, t.iterations.front().gradient_norm);  // the trial's: the same costate
    }
  }
}

// The discrepancy path's hand-over (OptimizerSummary::end_matrix, OptimizerOptions::start_matrix;
// docs/theory.md §7.2): a run with many parameters that ends on a step (a stall) hands the matrix of
// that step on; the next weight's run from its end starts on it without evaluating
// one and reaches the minimum a run evaluating its own start reaches. Given the very matrix the
// run would evaluate, the same run bit for bit; given a poor one (a thousand times too stiff: steps
// too short to gain anything), the start's own matrix is taken before anything is concluded.
TEST(GaussNewton, TheNextWeightsRunStartsOnTheMatrixTheLastOneEndedWith) {
  const auto sc = sections_scenario("0", 24, 8, 0.01);
  const auto p = make_problem(sc, std::nullopt);
  const long points = p->data.z.size();
  OptimizerOptions oo;
  oo.method = scoleid::io::Method::GaussNewton;
  oo.continuation = false;
  oo.smoothness_chains = {std::vector<int>(24)};
  for (int k = 0; k < 24; ++k) oo.smoothness_chains[0][static_cast<std::size_t>(k)] = k;
  oo.smoothness_weight = 1.0;
  Objective o(p->model(), *p->params, p->signals, p->data, p->objective_options);
  const OptimizerSummary first = minimize(o, p->params->initial() * 1.1, oo);
  std::printf("beta 1: %s; end matrix %s\n", first.BriefReport().c_str(), first.end_matrix.size() ? "handed on" : "none");
  ASSERT_EQ(first.termination, OptimizerSummary::Termination::CostStalled);
  ASSERT_EQ(first.end_matrix.rows(), 24);
  // The next weight, from the end: on the handed matrix, and on its own.
  OptimizerOptions next = oo;
  next.smoothness_weight = 0.1;
  auto run_from = [&](const MatrixXd& start_matrix, long& columns, int max_iterations = 200) {
    Objective fresh(p->model(), *p->params, p->signals, p->data, p->objective_options);
    OptimizerOptions n = next;
    n.start_matrix = start_matrix;
    n.max_iterations = max_iterations;
    const OptimizerSummary s = minimize(fresh, first.q, n);
    columns = fresh.counters().sensitivity_solves;
    return s;
  };
  long c_handed = 0, c_own = 0, c_poor = 0, c_start = 0;
  const OptimizerSummary handed = run_from(first.end_matrix, c_handed), own = run_from(MatrixXd(), c_own);
  const OptimizerSummary poor = run_from(1e3 * first.end_matrix, c_poor);
  std::printf("beta 0.1 on the handed matrix: %s, %ld tangent columns; on its own: %s, %ld; on a poor one: %s, %ld\n",
              handed.BriefReport().c_str(), c_handed, own.BriefReport().c_str(), c_own, poor.BriefReport().c_str(), c_poor);
  run_from(first.end_matrix, c_start, 0);
  EXPECT_EQ(c_start, 0);  // the start took its cost and gradient only
  {
    // On the same objective the start's cost and gradient are the last trial's, kept
    // (recalled_cost_and_gradient) where the run's q, exp(log q), is the point that trial took.
    OptimizerOptions n = next;
    n.start_matrix = first.end_matrix;
    n.max_iterations = 0;
    o.reset_counters();
    const OptimizerSummary s0 = minimize(o, first.q, n);
    const VectorXd x = first.q.array().log();
    const bool same_point = (VectorXd(x.array().exp()).array() == first.q.array()).all();
    EXPECT_EQ(o.counters().gradient_evaluations, same_point ? 0 : 1);
    EXPECT_EQ(o.counters().sensitivity_solves, 0);
    EXPECT_EQ(s0.cost - s0.prior_cost, first.cost - first.prior_cost);
  }
  for (const auto* s : {&handed, &poor}) {
    EXPECT_TRUE(s->converged()) << s->BriefReport();
    EXPECT_NEAR(s->cost, own.cost, 2.0 * own.cost / static_cast<double>(points));
    EXPECT_LT((s->q.array() / own.q.array() - 1.0).abs().maxCoeff(), 1e-2);
  }
  EXPECT_EQ(c_handed % 24, 0);
  EXPECT_GE(c_poor, 24);  // the poor matrix was replaced
  // The matrix the run would evaluate at its start: the same run bit for bit, one matrix fewer.
  const VectorXd qx = first.q.array().log().exp();  // the optimiser's q (it works in log q)
  VectorXd g;
  MatrixXd H;
  Objective at_start(p->model(), *p->params, p->signals, p->data, p->objective_options);
  at_start.gradient_and_step_matrix(qx, g, H);
  long c_same = 0;
  const OptimizerSummary same = run_from(qx.asDiagonal() * H * qx.asDiagonal(), c_same);
  EXPECT_EQ(c_same, c_own - 24);
  ASSERT_EQ(same.iterations.size(), own.iterations.size());
  for (std::size_t i = 0; i < own.iterations.size(); ++i) {
    EXPECT_EQ(same.iterations[i].cost, own.iterations[i].cost) << i;
    EXPECT_TRUE(same.iterations[i].q == own.iterations[i].q) << i;
  }
  // A matrix of another size is not taken.
  long c_wrong = 0;
  run_from(MatrixXd::Identity(5, 5), c_wrong, 0);
  EXPECT_EQ(c_wrong, 24);
}

TEST(SmoothnessPrior, EveryOptimiserReachesTheSameMinimiser) {
  // The prior enters the explicit Gauss–Newton matrix as β LᵀL, the matrix-free product as β LᵀL v
  // and the gradient methods' cost and gradient as its value and β LᵀL x: on the same cost (EI on 8
  // sections, 4 sensors, 1 % noise, β = 10⁻²) every optimiser must stop at the same minimiser, with
  // the same split of the cost into data and prior.
  RunOptions ro;
  ro.verbose = false;
  ro.compute_std = false;
  std::map<std::string, RunResult> out;
  Eigen::Index points = 1;
  for (const std::string method : {"gauss-newton", "gauss-newton-krylov", "lbfgs"}) {
    auto sc = sections_scenario("1e-2", 8, 4, 0.01);
    sc.identification.method = *scoleid::io::parse<scoleid::io::Method>(method);
    sc.identification.restarts = 0;
    sc.identification.max_iterations = 200;
    auto p = make_problem(sc, std::nullopt);
    points = p->data.z.size();
    out[method] = run_identification(*p, ro);
    const auto& r = out[method];
    std::printf("%-20s %s; cost %.8e (prior %.6e), RMS error %.3e\n", method.c_str(), r.summary.BriefReport().c_str(),
                r.summary.cost, r.summary.prior_cost, rms_error(r));
    EXPECT_TRUE(r.summary.converged()) << method;
    EXPECT_GT(r.summary.prior_cost, 0.0) << method;
  }
  // Gauss–Newton stops once an accepted step lowers J by less than J / (data points) (optimizers.h).
  // The matrix-free run agrees with it to that, and the sections to 1e-3 (their std at 1 % noise is
  // tens of percent). L-BFGS goes on past it (measured: 1.3e-3 lower, about two such gains, the
  // sections 1.2e-3 apart).
  const double stall = 1.0 / static_cast<double>(points);
  const auto& a = out["gauss-newton"];
  for (const auto& [method, tol, cost_gains, prior_tol] :
       {std::tuple<std::string, double, double, double>{"gauss-newton-krylov", 1e-3, 1.0, 2e-3}, {"lbfgs", 1e-2, 5.0, 2e-2}}) {
    const auto& b = out[method];
    const double dq = (a.estimate.array() / b.estimate.array() - 1.0).abs().maxCoeff();
    std::printf("%s: largest relative difference of the estimates %.3e; prior shares %.6e and %.6e\n", method.c_str(), dq,
                a.summary.prior_cost, b.summary.prior_cost);
    EXPECT_LT(dq, tol) << method;
    EXPECT_NEAR(a.summary.cost, b.summary.cost, cost_gains * stall * b.summary.cost) << method;
    EXPECT_NEAR(a.summary.prior_cost, b.summary.prior_cost, prior_tol * b.summary.prior_cost) << method;
  }
}

// With more than 16 parameters explicit Gauss–Newton takes a trial point's cost alone and the
// matrix only where a point is accepted (optimizers.cpp, ExplicitStep): EI on 24 sections with the
// prior (β = 10⁻², 4 sensors, 1 % noise) costs at most P tangent columns per accepted point plus
// the start, and reaches the minimiser the matrix-free method reaches from the same start.
TEST(SmoothnessPrior, ManyParametersTakeTheMatrixOnlyAtAcceptedPoints) {
  auto sc = sections_scenario("1e-2", 24, 4, 0.01);
  sc.identification.elements = 24;
  auto p = make_problem(sc, std::nullopt);
  std::map<std::string, OptimizerSummary> out;
  for (const auto method : {scoleid::io::Method::GaussNewton, scoleid::io::Method::GaussNewtonKrylov}) {
    Objective o(p->model(), *p->params, p->signals, p->data, p->objective_options);
    OptimizerOptions oo;
    oo.method = method;
    oo.max_iterations = 200;
    oo.smoothness_weight = 1e-2;
    oo.smoothness_chains = section_families(p->params->names());
    ASSERT_EQ(oo.smoothness_chains.size(), 1u);
    const OptimizerSummary s = minimize(o, p->params->initial(), oo);
    const auto& k = o.counters();
    std::printf("%-20s %s; %ld state solves, %ld tangent columns\n", scoleid::io::to_string(method),
                s.BriefReport().c_str(), k.forward_solves, k.sensitivity_solves);
    EXPECT_TRUE(s.converged()) << s.BriefReport();
    if (method == scoleid::io::Method::GaussNewton) {
      // The matrix at the start and at every accepted point, except the last one where the run
      // ended on its step (its gradient then not evaluated).
      const bool last_taken = std::isfinite(s.iterations.back().gradient_norm);
      EXPECT_EQ(k.sensitivity_solves, 24L * (s.iterations_done + (last_taken ? 1 : 0)));
      EXPECT_GE(k.forward_solves, s.iterations_done + 1);
    }
    out[scoleid::io::to_string(method)] = s;
  }
  const auto& a = out["gauss-newton"];
  const auto& b = out["gauss-newton-krylov"];
  const double stall = 1.0 / static_cast<double>(p->data.z.size());
  const double dq = (a.q.array() / b.q.array() - 1.0).abs().maxCoeff();
  std::printf("largest relative difference of the estimates %.3e; costs %.8e and %.8e\n", dq, a.cost, b.cost);
  EXPECT_LT(dq, 1e-2);
  EXPECT_LE(a.cost, b.cost * (1.0 + stall));  // the explicit step at least as far down
}

// The noise's share of the cost (docs/theory.md §7.8): for unit white noise n at the samples, ∫ñ²
// of its cubic interpolant has mean white_noise_integral and variance
// white_noise_integral_variance (a quadratic form nᵀQn: 2 Σ Q_ab², above the independent-sample
// value). Checked against 4000 draws, each integrated by 5-point Gauss–Legendre per interval.
TEST(NoiseIntegral, MeanAndVarianceMatchMonteCarlo) {
  Measurements m;
  m.names = {"n"};
  const int N = 101;
  for (int i = 0; i < N; ++i) m.t.push_back(0.01 * i);
  m.z = Eigen::MatrixXd::Zero(N, 1);
  const double W = m.white_noise_integral(0.0, 1.0), V = m.white_noise_integral_variance(0.0, 1.0);
  static const double gx[5] = {0.04691007703066800, 0.2307653449471585, 0.5, 0.7692346550528415, 0.9530899229693320};
  static const double gw[5] = {0.1184634425280945, 0.2393143352496832, 0.2844444444444444, 0.2393143352496832, 0.1184634425280945};
  std::mt19937_64 rng(7);
  std::normal_distribution<double> g(0.0, 1.0);
  const int draws = 4000;
  double s1 = 0, s2 = 0;
  for (int d = 0; d < draws; ++d) {
    for (int i = 0; i < N; ++i) m.z(i, 0) = g(rng);
    double I = 0;
    for (int i = 0; i + 1 < N; ++i)
      for (int k = 0; k < 5; ++k) {
        double v = 0;
        m.eval(m.t[static_cast<std::size_t>(i)] + gx[k] * 0.01, &v);
        I += gw[k] * 0.01 * v * v;
      }
    s1 += I;
    s2 += I * I;
  }
  const double mean = s1 / draws, var = s2 / draws - mean * mean;
  // Independent samples' value for comparison: 2 Σ Q_aa² <= 2 Σ Q_ab².
  std::printf("E: formula %.5f, sampled %.5f; Var: formula %.6f, sampled %.6f (2W^2/N would be %.6f)\n", W, mean, V, var,
              2.0 * W * W / N);
  EXPECT_NEAR(mean, W, 4.0 * std::sqrt(V / draws));
  EXPECT_NEAR(var / V, 1.0, 0.12);  // sampling error of a variance from 4000 draws: ~ 2.2 % · √(kurtosis/2)
  EXPECT_GT(V, 2.0 * W * W / N);
}

// The prior's bias in the interval (interval.h, smoothing shift): with the discrepancy weight the
// sections are pulled together by more than the data's std (the std is the data's alone); the
// refit at a tenth of the weight measures that pull, and the interval that includes it covers
// every section the Fisher test does not flag.
TEST(SmoothnessPrior, IntervalHoldsThePriorsBias) {
  RunOptions ro;
  ro.verbose = false;
  ro.compute_std = true;
  // EI on 8 sections seen by 8 sensors at 0.1 % noise: the data's std is small beside the pull.
  auto p = make_problem(sections_scenario("discrepancy", 8, 8, 1e-3), std::nullopt);
  const RunResult r = run_identification(*p, ro);
  ASSERT_TRUE(r.smoothness_met);
  ASSERT_GT(r.smoothness_weight, 0.0);
  int covered = 0, assessed = 0, beyond_std = 0, covered_without = 0;
  double largest_shift = 0.0;
  for (std::size_t i = 0; i < r.names.size(); ++i) {
    const auto ie = static_cast<Eigen::Index>(i);
    const double truth = r.truth.at(r.names[i]), err = std::abs(r.estimate[ie] - truth);
    const double hw = r.interval.half_width[ie], shift = r.interval.smoothing_shift[ie];
    std::printf("%-6s error %.3e  2 std %.3e  smoothing shift %.3e  half-width %.3e  %s\n", r.names[i].c_str(),
                err / truth, r.interval.noise[ie] / truth, shift / truth, hw / truth,
                r.ident.identifiable[i] ? "" : "(flagged)");
    largest_shift = std::max(largest_shift, shift / truth);
    if (!r.ident.identifiable[i] || !std::isfinite(hw)) continue;
    ++assessed;
    covered += err <= hw;
    covered_without += err <= hw - shift;
    beyond_std += err > r.interval.noise[ie];
  }
  std::printf("weight %.0e: %d of %d assessed sections covered (%d without the smoothing shift); %d beyond 2 std; "
              "largest smoothing shift %.3e\n",
              r.smoothness_weight, covered, assessed, covered_without, beyond_std, largest_shift);
  ASSERT_GT(assessed, 0);
  EXPECT_GT(beyond_std, 0) << "the prior's pull should exceed the data's 2 std somewhere in this case";
  EXPECT_EQ(covered, assessed);
  EXPECT_LT(covered_without, assessed);  // the term is what makes the interval hold
}
