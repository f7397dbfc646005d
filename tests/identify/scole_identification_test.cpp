// Ladder step 4 for SCOLE: the paper's SCOLE cases on synthetic data from a mesh twice as fine
// (and a time step four times finer) than the identifier's.
//   Case I  (paper-scole-1): q1 = EI/ρA, q2 = 1/ρA from the paper's start; paper: 14 iterations.
//   Case II (paper-scole-2): EI, ρA, ρI_ψ, ζ. What the scenario's sensors can determine is shown
//   at the truth, parameter by parameter: the relative change of a parameter whose effect on the
//   outputs equals the identifier's own discretisation residual (the Cramér–Rao std with that
//   residual as the noise level). A parameter whose resolution is coarser than the accuracy asked
//   for is reported as not identifiable from these data instead of being tuned for.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "scoleid/identify/identify_run.h"
#include "test_support.h"
#include "scoleid/identify/scole_model.h"

using namespace scoleid::identify;
using test_support::first_within;
using test_support::max_rel_error;

TEST(ScoleIdentification, CaseOneReachesOneInTenThousandWithinHalfThePaperIterations) {
  const auto t0 = std::chrono::steady_clock::now();
  auto p = make_problem(scoleid::io::load_scenario("paper-scole-1"), std::nullopt);
  RunOptions ro;
  ro.verbose = false;
  ro.compute_std = false;
  const RunResult r = run_identification(*p, ro);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  for (const auto& it : r.summary.iterations)
    std::printf("  %2d  q1 %.8e  q2 %.8e  J %.6e  max error %.3e\n", it.k, it.q[0], it.q[1], it.cost, max_rel_error(*p, it.q));
  const int k = first_within(*p, r, 1e-4);
  std::printf("  within 1e-4 at iteration %d (paper: 14); final max error %.3e; %s; %.2f s end to end\n", k,
              max_rel_error(*p, r.estimate), r.summary.BriefReport().c_str(), wall);
  EXPECT_GE(k, 1);
  EXPECT_LE(k, 7);
  EXPECT_LT(max_rel_error(*p, r.estimate), 1e-4);
  EXPECT_TRUE(r.summary.converged());
}

TEST(ScoleIdentification, CaseTwoResolutionOfEachParameterAtTheTruth) {
  // Identifier at the true parameters against the finer-mesh data: the residual r is the
  // identifier's discretisation error. Resolution of parameter i: ‖r‖ / ‖∂y/∂ln q_i‖.
  auto sc = scoleid::io::load_scenario("paper-scole-2");
  auto p = make_problem(sc, std::nullopt);
  const VectorXd q = p->params->truth();
  Objective obj(p->fe.model, *p->params, p->signals, p->data, p->objective_options);
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
  std::printf("  discretisation residual at the truth: %.3e of the signal\n", std::sqrt(r2 / y2));
  std::map<std::string, double> resolution;
  for (int j = 0; j < q.size(); ++j) {
    const auto& n = p->params->names()[static_cast<std::size_t>(j)];
    resolution[n] = std::sqrt(r2 / g2[j]);
    std::printf("  %-10s output sensitivity %.3e of the signal per unit relative change; resolution %.3e\n", n.c_str(),
                std::sqrt(g2[j] / y2), resolution[n]);
  }
  // Stiffness and mass per length: determined well below 1e-4.
  EXPECT_LT(resolution.at("EI"), 1e-4);
  EXPECT_LT(resolution.at("rho_A"), 1e-4);
  // ρI_ψ adds 118 slug ft² of polar inertia to the reflector's 27 400 about the mast axis: the
  // first torsion frequency moves by 7e-4 per unit relative change, so its resolution at the
  // identifier's default step is ~3e-3 (the residual is mostly time-step error; a quarter of the
  // step lowers it about twelvefold).
  EXPECT_GT(resolution.at("rho_I_psi"), 1e-4) << "rho_I_psi became identifiable to 1e-4: update this test and the report";
  // ζ enters as c = 2ζ√(ρA·EI): ζ carries ft², and a mode of wavenumber k has damping ratio ζ k².
  // For the modes these pulses excite that is 1e-7 … 1e-5, so ζ cannot be identified to 1e-4 from
  // 20 s of these sensors: reported, not tuned for.
  const ScoleFE fe = build_scole(sc.scole, sc.identification.elements, {}, {}, "test");
  const AssembledModel a = assemble(fe.model, scole_coefficients(sc.scole));
  Eigen::GeneralizedSelfAdjointEigenSolver<MatrixXd> es{MatrixXd(a.K), MatrixXd(a.M)};
  const double wmax = std::sqrt(es.eigenvalues().maxCoeff());
  std::printf("  modal damping ratios of the first flexible modes:");
  double zmax = 0.0;
  int shown = 0;
  for (int i = 0; i < es.eigenvalues().size() && shown < 8; ++i) {
    const double w2 = es.eigenvalues()[i];
    if (!(w2 > 0) || std::sqrt(w2) < 1e-7 * wmax) continue;
    const VectorXd phi = es.eigenvectors().col(i);
    const double z = phi.dot(a.D * phi) / (2.0 * std::sqrt(w2) * phi.dot(a.M * phi));
    zmax = std::max(zmax, z);
    std::printf(" %.2e", z);
    ++shown;
  }
  std::printf("\n");
  EXPECT_LT(zmax, 1e-4);
  EXPECT_GT(resolution.at("zeta"), 1e-4) << "zeta became identifiable: update this test and the report";
}

TEST(ScoleIdentification, CaseTwoFromThePaperStartRecoversWhatTheDataDetermineAndFlagsTheRest) {
  // From the paper's start: EI, ρA and ρI_ψ to 1e-4; ζ (modal damping ratios ζβ_k² ≈ 1e-7..1e-5
  // on a 130 ft mast) is flagged not identifiable instead of being returned as an estimate.
  auto p = make_problem(scoleid::io::load_scenario("paper-scole-2"), std::nullopt);
  RunOptions ro;
  ro.verbose = false;
  const RunResult r = run_identification(*p, ro);
  std::printf("  %s\n", r.summary.BriefReport().c_str());
  for (std::size_t i = 0; i < r.names.size(); ++i) {
    const double e = r.estimate[static_cast<Eigen::Index>(i)] / p->true_values.at(r.names[i]) - 1.0;
    std::printf("  %-10s error %+.3e std %.3e identifiable %d\n", r.names[i].c_str(), e,
                r.ident.std[static_cast<Eigen::Index>(i)], static_cast<int>(r.ident.identifiable[i]));
    if (r.names[i] == "zeta") {
      EXPECT_FALSE(r.ident.identifiable[i]);
    } else {
      EXPECT_TRUE(r.ident.identifiable[i]) << r.names[i];
      EXPECT_LT(std::abs(e), 1e-4) << r.names[i];
      // the reported std is a real number of the size of the error (residual-based noise level)
      EXPECT_TRUE(std::isfinite(r.ident.std[static_cast<Eigen::Index>(i)])) << r.names[i];
    }
  }
  EXPECT_TRUE(r.summary.converged());
}
