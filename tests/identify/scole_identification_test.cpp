// Ladder step 4 for SCOLE: the paper's SCOLE cases from the paper's starting values, on synthetic
// data from a mesh twice as fine (and a time step four times finer) than the identifier's.
//   Case I  (paper-scole-1): q1 = EI/ρA, q2 = 1/ρA; paper: 14 iterations; here at most 7.
//   Case II (paper-scole-2): EI, ρA, ρI_ψ, ζ; paper: 16 iterations; here at most 8 to 1e-4 for
//   every parameter the data determine. ζ is measured against what the identifier can resolve —
//   the output change of a 100 % change of ζ against the identifier's own discretisation
//   residual, and the modal damping ζ gives against the damping of the integrator itself — and it
//   is flagged not identifiable instead of being tuned for.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <chrono>
#include <cmath>
#include <complex>
#include <cstdio>

#include "scoleid/identify/time/esdirk_stepper.h"
#include "scoleid/identify/run/identify_run.h"
#include "scoleid/identify/fe/scole_model.h"
#include "test_support.h"

using namespace scoleid::identify;
using test_support::first_within;
using test_support::max_rel_error;

namespace {

// Damping ratio the integrator adds to an undamped mode of frequency ω at step h:
// |R(iωh)| = exp(−ζ_num ω h), R(z) = 1 + z bᵀ (I − z A)⁻¹ 1 the table's stability function.
double numerical_damping(const ButcherTable& B, double wh) {
  const int s = B.stages;
  Eigen::MatrixXcd A(s, s);
  Eigen::VectorXcd b(s);
  for (int i = 0; i < s; ++i) {
    b[i] = B.b[static_cast<std::size_t>(i)];
    for (int j = 0; j < s; ++j) A(i, j) = B.a(i, j);
  }
  const std::complex<double> z(0.0, wh);
  const Eigen::MatrixXcd I = Eigen::MatrixXcd::Identity(s, s);
  const Eigen::VectorXcd y = (I - z * A).partialPivLu().solve(Eigen::VectorXcd::Ones(s));
  const std::complex<double> R = 1.0 + z * (b.transpose() * y)(0);
  return -std::log(std::abs(R)) / wh;
}

}  // namespace

TEST(ScoleIdentification, CaseOneReachesOneInTenThousandWithinHalfThePaperIterations) {
  const auto t0 = std::chrono::steady_clock::now();
  auto p = make_problem(scoleid::io::load_scenario("paper-scole-1"), std::nullopt);
  RunOptions ro;
  ro.verbose = false;
  ro.compute_std = false;
  const RunResult r = run_identification(*p, ro);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  for (const auto& it : r.summary.iterations)
    std::printf("  %2d  q1 %.8e  q2 %.8e  J %.6e  horizon %5.2f  max error %.3e\n", it.k, it.q[0], it.q[1], it.cost, it.horizon,
                max_rel_error(*p, it.q));
  const int k = first_within(*p, r, 1e-4);
  std::printf("  within 1e-4 at iteration %d (paper: 14); final max error %.3e; %s; %.2f s end to end\n", k,
              max_rel_error(*p, r.estimate), r.summary.BriefReport().c_str(), wall);
  EXPECT_GE(k, 1);
  EXPECT_LE(k, 7);
  EXPECT_LT(max_rel_error(*p, r.estimate), 1e-4);
  EXPECT_TRUE(r.summary.converged());
}

TEST(ScoleIdentification, CaseTwoZetaIsBelowWhatTheIdentifierResolves) {
  // At the true parameters against the finer-mesh data the residual r is the identifier's
  // discretisation error. ζ enters as c = 2ζ√(ρA·EI): a bending mode of wavenumber β gets the
  // damping ratio ζβ² (ζ carries ft²), ~1e-7…1e-5 for the modes these pulses excite.
  auto sc = scoleid::io::load_scenario("paper-scole-2");
  auto p = make_problem(sc, std::nullopt);
  const VectorXd q = p->params->truth();
  Objective obj(p->model(), *p->params, p->signals, p->data, p->objective_options);
  const MatrixXd Y = obj.predict(q);
  const MatrixXd G = obj.output_sensitivities(q);  // (samples·sensors) × P, row-major by sample
  const int ns = p->data.sensors();
  // Weighted as the cost weighs the sensors: each by its RMS.
  VectorXd w(ns);
  for (int k = 0; k < ns; ++k) w[k] = 1.0 / std::sqrt(p->data.z.col(k).squaredNorm() / static_cast<double>(p->data.z.rows()));
  double r2 = 0.0, y2 = 0.0;
  VectorXd g2 = VectorXd::Zero(q.size());
  for (Eigen::Index i = 0; i < Y.rows(); ++i)
    for (int k = 0; k < ns; ++k) {
      r2 += std::pow(w[k] * (Y(i, k) - p->data.z(i, k)), 2);
      y2 += std::pow(w[k] * Y(i, k), 2);
      for (int j = 0; j < q.size(); ++j) g2[j] += std::pow(w[k] * q[j] * G(i * ns + k, j), 2);
    }
  const double residual = std::sqrt(r2 / y2);
  std::printf("  discretisation residual at the truth: %.3e of the signal\n", residual);
  // The report's analysis at the truth (noise level = residual): Cramér–Rao std and resolution.
  const Identifiability id = analyse_identifiability(obj, sc.sensors, q);
  std::map<std::string, double> change, bound;
  for (int j = 0; j < q.size(); ++j) {
    const auto& n = p->params->names()[static_cast<std::size_t>(j)];
    change[n] = std::sqrt(g2[j] / y2);
    bound[n] = id.resolution[j] / q[j];
    std::printf("  %-10s output change per 100 %% change %.3e of the signal; relative std %.3e, resolution %.3e%s\n",
                n.c_str(), change[n], id.std[j] / q[j], bound[n], id.identifiable[static_cast<std::size_t>(j)] ? "" : "  NOT IDENTIFIABLE");
  }
  // Stiffness, mass per length and torsional inertia: determined.
  for (int j = 0; j < 3; ++j) EXPECT_TRUE(id.identifiable[static_cast<std::size_t>(j)]) << p->params->names()[static_cast<std::size_t>(j)];
  // ζ: doubling it moves the outputs by less than the identifier's own residual, so a model error
  // of the residual's size could shift ζ by more than 100 % (its resolution): flagged even at its
  // true value.
  EXPECT_LT(change.at("zeta"), residual);
  EXPECT_GT(bound.at("zeta"), 0.5);
  EXPECT_FALSE(id.identifiable[3]) << "zeta";

  // Where the residual comes from: the identifier's L-stable step damps every mode by itself, and
  // for the modes that carry ζ that damping is comparable to or larger than ζβ²; the data,
  // integrated at a quarter of the step, carry 1/64 of it. To give ζ to 1e-4 the difference
  // would have to stay below 1e-4 of ζβ².
  const ScoleFE fe = build_scole(sc.scole, sc.identification.elements, {}, {}, "test");
  const AssembledModel a = assemble(fe.model, scole_coefficients(sc.scole));
  Eigen::GeneralizedSelfAdjointEigenSolver<MatrixXd> es{MatrixXd(a.K), MatrixXd(a.M)};
  const double wmax = std::sqrt(es.eigenvalues().maxCoeff());
  const ButcherTable table = ButcherTable::arkode_dirk(p->objective_options.solver.dirk_table);
  const double h = p->objective_options.solver.step;
  std::printf("  %4s %9s %11s %13s %13s\n", "mode", "f [Hz]", "zeta_k", "num. h", "num. h/4");
  int shown = 0;
  double worst = 1e300;
  for (int i = 0; i < es.eigenvalues().size() && shown < 8; ++i) {
    const double w2 = es.eigenvalues()[i];
    if (!(w2 > 0) || std::sqrt(w2) < 1e-7 * wmax) continue;
    const double om = std::sqrt(w2);
    const VectorXd phi = es.eigenvectors().col(i);
    const double z = phi.dot(a.D * phi) / (2.0 * om * phi.dot(a.M * phi));
    const double zh = numerical_damping(table, om * h), zq = numerical_damping(table, om * h / 4);
    std::printf("  %4d %9.4f %11.3e %13.3e %13.3e\n", ++shown, om / (2 * M_PI), z, zh, zq);
    EXPECT_LT(z, 1e-4);
    worst = std::min(worst, (zh - zq) / z);
  }
  std::printf("  integrator damping (step h less step h/4) / zeta_k: at least %.2f over these modes\n", worst);
  EXPECT_GT(worst, 1e-4);
}

TEST(ScoleIdentification, CaseTwoFromThePaperStartInAtMostEightIterations) {
  // From the paper's start: every parameter the data determine within 1e-4 of the truth in at
  // most 8 Gauss–Newton iterations (all iterations counted, on every horizon); ζ recovered to
  // 1e-4 or flagged not identifiable — never returned silently.
  // ρI_ψ (118 slug ft² of the 27 400 the torsion mode carries) ends near 4e-5, but its
  // resolution is ~5e-3: what is left is discretisation bias, partly absorbed by ζ, which
  // the fit drives towards 0 to offset the integrator's own damping. With ζ held at its true
  // value ρI_ψ comes out 1.6e-3 high, and with a 20-element identifier mesh 2e-4 low — so a
  // change of discretisation can move ρI_ψ past 1e-4 while staying inside its resolution.
  const auto t0 = std::chrono::steady_clock::now();
  auto p = make_problem(scoleid::io::load_scenario("paper-scole-2"), std::nullopt);
  RunOptions ro;
  ro.verbose = false;
  const RunResult r = run_identification(*p, ro);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const int P = static_cast<int>(r.names.size());
  auto error = [&](const VectorXd& qq, int i) {
    return qq[i] / p->true_values.at(r.names[static_cast<std::size_t>(i)]) - 1.0;
  };
  int k_within = -1;
  double previous_horizon = 0.0;
  for (const auto& it : r.summary.iterations) {
    std::printf("  %2d  horizon %5.2f  J %.4e ", it.k, it.horizon, it.cost);
    double worst = 0.0;
    for (int i = 0; i < P; ++i) {
      std::printf(" %s %+.2e", r.names[static_cast<std::size_t>(i)].c_str(), error(it.q, i));
      if (r.ident.identifiable[static_cast<std::size_t>(i)]) worst = std::max(worst, std::abs(error(it.q, i)));
    }
    std::printf("\n");
    if (k_within < 0 && worst <= 1e-4) k_within = it.k;
    EXPECT_GE(it.horizon, previous_horizon) << "the horizon only grows";
    previous_horizon = it.horizon;
  }
  std::printf("  identifiable parameters within 1e-4 at iteration %d (paper: 16); %s; %.2f s end to end\n", k_within,
              r.summary.BriefReport().c_str(), wall);
  EXPECT_GE(k_within, 1);
  EXPECT_LE(k_within, 8);
  // The fit started on a part of the record and ended on all of it.
  EXPECT_LT(r.summary.iterations.front().horizon, p->data.t.back());
  EXPECT_EQ(r.summary.iterations.back().horizon, p->data.t.back());
  for (int i = 0; i < P; ++i) {
    const auto& n = r.names[static_cast<std::size_t>(i)];
    const double e = error(r.estimate, i);
    std::printf("  %-10s error %+.3e std %.3e resolution %.3e identifiable %d\n", n.c_str(), e, r.ident.std[i],
                r.ident.resolution[i], static_cast<int>(r.ident.identifiable[static_cast<std::size_t>(i)]));
    if (n == "zeta") {
      EXPECT_TRUE(!r.ident.identifiable[static_cast<std::size_t>(i)] || std::abs(e) < 1e-4) << "zeta returned silently";
    } else {
      EXPECT_TRUE(r.ident.identifiable[static_cast<std::size_t>(i)]) << n;
      EXPECT_LT(std::abs(e), 1e-4) << n;
      EXPECT_TRUE(std::isfinite(r.ident.std[i])) << n;
    }
  }
  EXPECT_TRUE(r.summary.converged());
}
