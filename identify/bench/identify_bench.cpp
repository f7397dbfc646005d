// scole-identify-bench: the identifier's speed figures, measured side by side in one run.
//   1. adjoint gradient cost / one forward solve, for N = 2 and N = 64 stiffness sections, with
//      central finite differences beside it;
//   2. forward solve time vs elements (10, 20, 40, 80): growth exponent;
//   3. Case I (paper-beam-1) identification end to end, from data in memory and from the scenario;
//   4. SCOLE gradient/forward ratio at 20 elements per field;
//   5. paper-scole-2 end to end as `scole-identify --scenario paper-scole-2 --out DIR` runs it
//      (data synthesis, identification, identifiability, outputs), with the split;
//   6. the banded solve of P right-hand sides (the sensitivities' stage solves): P one-column
//      sweeps against one sweep over all P columns, on a beam's and SCOLE's Newton matrix.
// Each figure is the minimum over repetitions (wall clock, steady_clock). `--part K` (repeatable)
// runs only the parts named; the summary line then shows 0 for the others.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

#include "best_of.h"
#include "scoleid/identify/time/banded_cholesky.h"
#include "scoleid/identify/run/identify_run.h"

using namespace scoleid::identify;
using Clock = std::chrono::steady_clock;

namespace {

using bench::best_of;
using bench::best_of_alternating;

scoleid::io::Scenario sections_scenario(int N, int elements) {
  auto sc = scoleid::io::load_scenario("paper-beam-3");
  sc.name = "sections-" + std::to_string(N);
  sc.beam.EI.assign(static_cast<std::size_t>(N), 0.0);
  for (int k = 0; k < N; ++k) sc.beam.EI[static_cast<std::size_t>(k)] = 23000.0 * (1.0 + 0.5 * std::sin(0.37 * k));
  sc.identification.estimate.clear();
  sc.identification.initial.clear();
  for (int k = 1; k <= N; ++k) sc.identification.estimate.push_back("EI_" + std::to_string(k));
  sc.identification.initial["EI"] = 25000.0;
  sc.identification.elements = elements;
  sc.identification.data_elements = 2 * elements;
  // The same step for every N (compare like with like), short enough to resolve flexible mode
  // N + 2 = 66 at N = 64 (ω h = 0.9), which the identifier requires of a given step; 1 s record.
  sc.identification.time_step = 1e-4;
  sc.simulation.duration = 1.0;
  return sc;
}

// Factor of M + g D + g² K (g = 1 ms) of a problem's model at its starting values.
BandedCholesky newton_factor(const Problem& p) {
  VectorXd c;
  MatrixXd dc;
  p.params->coefficients(p.params->initial(), c, dc);
  const AssembledModel ops = assemble(p.model(), c);
  const double g = 1e-3;
  const SparseMatrix A = ops.M + g * ops.D + g * g * ops.K;
  BandedCholesky chol;
  chol.resize(static_cast<int>(A.rows()), BandedCholesky::shape(A));
  chol.assign(A);
  if (!chol.factorize()) throw std::runtime_error("bench: Newton matrix not positive definite");
  return chol;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<int> parts;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--part" && i + 1 < argc && std::atoi(argv[i + 1]) >= 1 && std::atoi(argv[i + 1]) <= 6) {
      parts.push_back(std::atoi(argv[++i]));
    } else {
      std::fprintf(stderr, "usage: scole-identify-bench [--part K]...  (K = 1..6; all parts when none is named)\n");
      return a == "--help" || a == "-h" ? 0 : 2;
    }
  }
  const auto want = [&](int k) { return parts.empty() || std::find(parts.begin(), parts.end(), k) != parts.end(); };
  std::printf("scole-identify-bench (wall clock, best of repetitions)\n\n");

  if (want(1)) std::printf("1. Gradient cost relative to one forward solve (64 elements, 1 s, h = 1e-4)\n");
  if (want(1)) std::printf("%6s %12s %12s %10s %12s %10s\n", "N", "forward [s]", "adjoint [s]", "ratio", "central FD", "ratio");
  double ratio_n2 = 0, ratio_n64 = 0, grad_n2 = 0, grad_n64 = 0;
  for (int N : {2, 64}) {
    if (!want(1)) break;
    auto p = make_problem(sections_scenario(N, 64), std::nullopt);
    Objective obj(p->model(), *p->params, p->signals, p->data, p->objective_options);
    const VectorXd q = p->params->initial();
    VectorXd g;
    const auto [tf, tg] = best_of_alternating(
        7, [&] { obj.cost(q); }, [&] { obj.cost_and_gradient(q, g); });
    const double tfd = 2.0 * N * tf;  // 2N forward solves
    std::printf("%6d %12.4f %12.4f %10.2f %12.4f %10.1f\n", N, tf, tg, tg / tf, tfd, tfd / tf);
    obj.reset_counters();
    obj.cost_and_gradient(q, g);
    const auto& c = obj.counters();
    std::printf("%6s gradient's split: forward %.4f, costate %.4f, quadrature %.4f s (%s)\n", "", c.forward_seconds,
                c.costate_seconds, c.quadrature_seconds, c.checkpointed_passes ? "checkpointed" : "stored");
    (N == 2 ? ratio_n2 : ratio_n64) = tg / tf;
    (N == 2 ? grad_n2 : grad_n64) = tg;
  }
  if (want(1)) std::printf("   adjoint gradient time N=64 / N=2: %.2f\n\n", grad_n64 / grad_n2);

  if (want(2)) std::printf("2. Forward solve vs elements (paper-beam-1 geometry, 10 s, h = 0.01)\n");
  if (want(2)) std::printf("%10s %8s %12s %12s\n", "elements", "dofs", "forward [s]", "growth exp");
  double prev = 0;
  int prev_ne = 0;
  for (int ne : {10, 20, 40, 80}) {
    if (!want(2)) break;
    auto sc = scoleid::io::load_scenario("paper-beam-1");
    sc.identification.elements = ne;
    sc.identification.data_elements = 2 * ne;
    sc.identification.time_step = 0.01;
    auto p = make_problem(sc, std::nullopt);
    Objective obj(p->model(), *p->params, p->signals, p->data, p->objective_options);
    const VectorXd q = p->params->initial();
    const double t = best_of(3, [&] { obj.cost(q); });
    if (prev > 0)
      std::printf("%10d %8d %12.4f %12.2f\n", ne, p->model().ndof, t, std::log(t / prev) / std::log(double(ne) / prev_ne));
    else
      std::printf("%10d %8d %12.4f %12s\n", ne, p->model().ndof, t, "-");
    prev = t;
    prev_ne = ne;
  }

  if (want(3)) std::printf("\n3. paper-beam-1 identification (Gauss-Newton, 10 elements)\n");
  auto sc = scoleid::io::load_scenario("paper-beam-1");
  double t_ident = want(3) ? 1e300 : 0.0, t_total = want(3) ? 1e300 : 0.0;
  int iters = 0;
  for (int r = 0; r < 3 && want(3); ++r) {
    const auto t0 = Clock::now();
    auto p = make_problem(sc, std::nullopt);
    const auto t1 = Clock::now();
    RunOptions ro;
    ro.verbose = false;
    ro.compute_std = false;
    const RunResult res = run_identification(*p, ro);
    const auto t2 = Clock::now();
    iters = res.summary.iterations_done;
    t_ident = std::min(t_ident, std::chrono::duration<double>(t2 - t1).count());
    t_total = std::min(t_total, std::chrono::duration<double>(t2 - t0).count());
  }
  if (want(3)) std::printf("   identification from data in memory: %.3f s (%d iterations)\n", t_ident, iters);
  if (want(3)) std::printf("   with data synthesis (20 elements):  %.3f s\n", t_total);

  if (want(4)) std::printf("\n4. SCOLE (paper-scole-2 parameters EI, rho_A, rho_I_psi, zeta; 20 elements per field, 20 s)\n");
  double scole_ratio = 0;
  if (want(4)) {
    auto ssc = scoleid::io::load_scenario("paper-scole-2");
    ssc.identification.elements = 20;
    ssc.identification.data_elements = 40;
    auto p = make_problem(ssc, std::nullopt);
    Objective obj(p->model(), *p->params, p->signals, p->data, p->objective_options);
    const VectorXd q = p->params->initial();
    VectorXd g;
    const auto [tf, tg] = best_of_alternating(
        15, [&] { obj.cost(q); }, [&] { obj.cost_and_gradient(q, g); });
    scole_ratio = tg / tf;
    obj.reset_counters();
    obj.cost_and_gradient(q, g);
    const auto& c = obj.counters();
    std::printf("   gradient's split: forward %.4f, costate %.4f, quadrature %.4f s (%s)\n", c.forward_seconds,
                c.costate_seconds, c.quadrature_seconds, c.checkpointed_passes ? "checkpointed" : "stored");
    std::printf("   %d DOFs, step %.2e s: forward %.4f s, adjoint gradient %.4f s, ratio %.2f\n", p->model().ndof,
                p->objective_options.solver.step, tf, tg, scole_ratio);
  }
  if (want(5)) std::printf("\n5. paper-scole-2 end to end (EI, rho_A, rho_I_psi, zeta from the paper's start; best of 3)\n");
  double e2e = 0;
  if (want(5)) {
    const auto dir = std::filesystem::temp_directory_path() / "scole-identify-bench";
    struct Split {
      double synth, ident, forward, costate, sens, quad, opt, fisher, out, total;
      int iters, within;
      long fwd_solves, sens_solves;
    } best{};
    for (int rep = 0; rep < 3; ++rep) {
      const auto t0 = Clock::now();
      auto p = make_problem(scoleid::io::load_scenario("paper-scole-2"), std::nullopt);
      const auto t1 = Clock::now();
      RunOptions ro;
      ro.verbose = false;
      const RunResult r = run_identification(*p, ro);
      const auto t2 = Clock::now();
      {
        scoleid::io::RunDirectory run_dir(dir.string(), output_files(), "scole-identify-bench");
        write_outputs(run_dir, *p, r);
        run_dir.commit();
      }
      const auto t3 = Clock::now();
      auto s = [](Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); };
      int within = -1;
      for (const auto& it : r.summary.iterations) {
        double worst = 0.0;
        for (int i = 0; i < it.q.size(); ++i)
          if (r.ident.identifiable[static_cast<std::size_t>(i)])
            worst = std::max(worst, std::abs(it.q[i] / p->true_values.at(r.names[static_cast<std::size_t>(i)]) - 1.0));
        if (within < 0 && worst <= 1e-4) within = it.k;
      }
      const Split cur{s(t0, t1), s(t1, t2), r.counters.forward_seconds, r.counters.costate_seconds,
                      r.counters.sensitivity_seconds, r.counters.quadrature_seconds, r.summary.wall_seconds,
                      r.identifiability_seconds, s(t2, t3), s(t0, t3), r.summary.iterations_done, within,
                      r.counters.forward_solves, r.counters.sensitivity_solves};
      if (rep == 0 || cur.total < best.total) best = cur;
    }
    std::filesystem::remove_all(dir);
    e2e = best.total;
    std::printf("   total %.3f s: data synthesis %.3f, identification %.3f (optimiser %.3f + identifiability %.3f), outputs %.3f\n",
                best.total, best.synth, best.ident, best.opt, best.fisher, best.out);
    std::printf("   solver time inside the identification: forward %.3f, costate %.3f, state+sensitivity %.3f, "
                "quadrature %.3f (%ld state solves, %ld sensitivities)\n",
                best.forward, best.costate, best.sens, best.quad, best.fwd_solves, best.sens_solves);
    std::printf("   %d iterations, identifiable parameters within 1e-4 at iteration %d\n", best.iters, best.within);
    // The step rule's choice against the third-order table at its own damping-bounded step, on the
    // same data, alternating (identification only: synthesis and outputs excluded).
    auto p = make_problem(scoleid::io::load_scenario("paper-scole-2"), std::nullopt);
    const IdentifierStep chosen = identifier_integration(p->scenario, p->model(), *p->params, p->signals);
    if (chosen.third_order_step < chosen.step) {
      RunOptions ro;
      ro.verbose = false;
      double worst[2] = {0.0, 0.0};
      auto run = [&](int which) {
        p->objective_options.solver.dirk_table = which == 0 ? chosen.dirk_table : -1;
        p->objective_options.solver.step = which == 0 ? chosen.step : chosen.third_order_step;
        const RunResult r = run_identification(*p, ro);
        for (int i = 0; i < r.estimate.size(); ++i)
          worst[which] = std::max(worst[which], std::abs(r.estimate[i] / p->true_values.at(r.names[static_cast<std::size_t>(i)]) - 1.0));
      };
      const auto [t4, t3] = best_of_alternating(3, [&] { run(0); }, [&] { run(1); });
      std::printf("   identification with %s at h = %.3g s: %.3f s, largest error %.2e; %s at its own bound h = %.3g s: "
                  "%.3f s, largest error %.2e; ratio %.2f\n",
                  ButcherTable::name(chosen.dirk_table).c_str(), chosen.step, t4, worst[0], ButcherTable::name(-1).c_str(),
                  chosen.third_order_step, t3, worst[1], t3 / t4);
    }
    // One thread per sweep against the automatic split (two when the machine has them), on the
    // same data, alternating; the estimates must agree bit for bit.
    {
      auto q = make_problem(scoleid::io::load_scenario("paper-scole-2"), std::nullopt);
      RunOptions ro;
      ro.verbose = false;
      VectorXd est[2];
      auto run = [&](int threads) {
        q->objective_options.sweep_threads = threads;
        est[threads == 1 ? 0 : 1] = run_identification(*q, ro).estimate;
      };
      const auto [t_one, t_auto] = best_of_alternating(3, [&] { run(1); }, [&] { run(0); });
      std::printf("   identification with one thread per sweep %.3f s, with the automatic split %.3f s: ratio %.2f; "
                  "estimates %s\n",
                  t_one, t_auto, t_one / t_auto, est[0] == est[1] ? "identical" : "DIFFER");
    }
  }
  if (want(6)) std::printf("\n6. Banded solve of P right-hand sides: P one-column sweeps / one P-column sweep (same results)\n");
  if (want(6)) std::printf("%-28s %6s %6s %6s %4s %14s %14s %8s\n", "matrix", "dofs", "band", "border", "P", "P x 1 [us]", "1 x P [us]",
              "ratio");
  double solve_ratio16 = 0;
  for (const char* which : {"beam, 64 elements", "paper-scole-2, 20 elements"}) {
    if (!want(6)) break;
    std::unique_ptr<Problem> p;
    if (which[0] == 'b') {
      p = make_problem(sections_scenario(2, 64), std::nullopt);
    } else {
      auto ssc = scoleid::io::load_scenario("paper-scole-2");
      ssc.identification.elements = 20;
      ssc.identification.data_elements = 40;
      p = make_problem(ssc, std::nullopt);
    }
    const BandedCholesky chol = newton_factor(*p);
    const int n = chol.size();
    for (int P : {1, 4, 16, 64}) {
      const MatrixXd R = MatrixXd::Random(n, P);
      MatrixXd X1 = R, XP = R;
      for (int j = 0; j < P; ++j) chol.solve_in_place(X1.col(j).data());
      chol.solve_in_place(XP.data(), P, n);
      if (X1 != XP) throw std::runtime_error("bench: the P-column solve differs from P one-column solves");
      // Each repetition solves a fresh copy of R (the copy, the same in both, is in both times).
      const int reps = std::max(1, 20000 / P);
      const double t1 = best_of(5, [&] {
        for (int r = 0; r < reps; ++r) {
          X1 = R;
          for (int j = 0; j < P; ++j) chol.solve_in_place(X1.col(j).data());
        }
      });
      const double tP = best_of(5, [&] {
        for (int r = 0; r < reps; ++r) {
          XP = R;
          chol.solve_in_place(XP.data(), P, n);
        }
      });
      std::printf("%-28s %6d %6d %6d %4d %14.2f %14.2f %8.2f\n", which, n, chol.half_bandwidth(), chol.border(), P, 1e6 * t1 / reps,
                  1e6 * tP / reps, t1 / tP);
      if (P == 16 && which[0] == 'b') solve_ratio16 = t1 / tP;
    }
  }

  std::printf("\nsummary: gradient/forward %.2f (N=2), %.2f (N=64), %.2f (SCOLE); N=64/N=2 gradient time %.2f; Case I %.3f s; "
              "paper-scole-2 end to end %.3f s; 16-column banded solve %.2fx faster than 16 one-column solves\n",
              ratio_n2, ratio_n64, scole_ratio, grad_n2 > 0 ? grad_n64 / grad_n2 : 0.0, t_ident, e2e, solve_ratio16);
  return 0;
}
