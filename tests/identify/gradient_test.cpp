// Ladder step 2: the costate gradient against central differences, the Gauss–Newton
// (forward-sensitivity) gradient and the SUNDIALS CVODES adjoint, for every parameter kind;
// and a Taylor test showing second-order decay of the remainder.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "test_support.h"
#include "scoleid/identify/inverse/cvodes_adjoint.h"
#include "scoleid/identify/run/problem.h"

using namespace scoleid::identify;
using test_support::Case;
using test_support::make_case;
using test_support::max_rel;

namespace {

// Small meshes and a 2 s horizon keep the dense CVODES reference cheap.
const char* kPaper = R"(name: grad-paper
beam: {length: 10, left: clamped, right: free, rho_A: 67, EI: 23000, zeta: 0.05, tip_mass: 30, tip_inertia: 5}
inputs: [{name: P, location: 10, signal: {type: haversine, amplitude: 10, t0: 0.05, width: 0.3}}]
sensors: [{name: w, location: 10}, {name: r, kind: rotation, location: 7}]
simulation: {duration: 2, sample_interval: 0.01}
identification: {parameterization: paper, estimate: [q1, q2, q3], initial: {rho_A: 60, EI: 20000, zeta: 0.08}, elements: 4}
)";
const char* kPhysical = R"(name: grad-physical
beam: {length: 10, left: clamped, right: free, rho_A: 67, EI: 23000, zeta: 0.05}
inputs: [{name: P, location: 6.3, signal: {type: step, amplitude: 10, t0: 0}}]
sensors: [{name: w, location: 10}]
simulation: {duration: 2, sample_interval: 0.01}
identification: {parameterization: physical, estimate: [rho_A, EI, zeta], initial: {rho_A: 60, EI: 20000, zeta: 0.08}, elements: 4}
)";
const char* kSections = R"(name: grad-sections
beam: {length: 10, left: pinned, right: pinned, rho_A: 67, EI: [23000, 30000, 26000, 35000], zeta: 0.02}
inputs: [{name: P, location: 3.3, signal: {type: pulse, amplitude: 50, t0: 0.1, width: 0.2}}]
sensors: [{name: a, location: 2.5}, {name: b, location: 7.5}]
simulation: {duration: 2, sample_interval: 0.01}
identification: {parameterization: physical, estimate: [EI_1, EI_2, EI_3, EI_4, rho_A, zeta], initial: {EI: 28000, rho_A: 70, zeta: 0.03}, elements: 8}
)";

void check_kind(const char* yaml) {
  // (1) Same integrator (ESDIRK, fixed step): costate vs central FD vs Gauss–Newton gradient.
  Case e = make_case(yaml, false);
  const VectorXd q = e.p->params->initial();
  VectorXd g_adj, g_gn;
  MatrixXd H;
  e.obj->cost_and_gradient(q, g_adj);
  e.obj->gauss_newton(q, g_gn, H);
  const VectorXd g_fd = e.obj->finite_difference_gradient(q, 1e-5);
  std::printf("  esdirk: adjoint vs FD %.2e, vs Gauss-Newton %.2e\n", max_rel(g_adj, g_fd), max_rel(g_adj, g_gn));
  EXPECT_LT(max_rel(g_adj, g_fd), 1e-4);
  EXPECT_LT(max_rel(g_gn, g_fd), 1e-4);
  // (2) Adaptive BDF at rtol 1e-10: costate vs the CVODES adjoint (CVodeF/CVodeB) and FD.
  Case b = make_case(yaml, true);
  VectorXd g_b;
  const double Jb = b.obj->cost_and_gradient(q, g_b);
  const CvodesAdjointResult ref = cvodes_adjoint_gradient(*b.obj, q, 1e-10);
  std::printf("  bdf: costate vs CVODES adjoint %.2e (J %.10e vs %.10e)\n", max_rel(g_b, ref.gradient), Jb, ref.cost);
  for (int i = 0; i < q.size(); ++i)
    std::printf("    %-6s costate %+.10e  cvodes %+.10e  fd(esdirk) %+.10e\n", e.p->params->names()[static_cast<std::size_t>(i)].c_str(),
                g_b[i], ref.gradient[i], g_fd[i]);
  EXPECT_LT(max_rel(g_b, ref.gradient), 1e-5);
  EXPECT_NEAR(Jb, ref.cost, 1e-6 * ref.cost);
}

}  // namespace

TEST(Gradient, PaperParametersWithTipBody) { check_kind(kPaper); }
TEST(Gradient, PhysicalParameters) { check_kind(kPhysical); }
TEST(Gradient, SectionalStiffnessMassAndDamping) { check_kind(kSections); }

TEST(Gradient, TaylorRemainderFallsAtSecondOrder) {
  // R(ε) = |J(q ∘ exp(ε d)) − J(q) − ε ∇J·(q ∘ d)| for a random direction d in log q.
  for (const char* yaml : {kPaper, kSections}) {
    Case e = make_case(yaml, false);
    const std::vector<double> R = test_support::taylor_remainders(*e.obj, e.p->params->initial(), 7);
    // Second order: the remainder quarters at each halving (ratio 4; first order would give 2).
    for (std::size_t k = 1; k < 5; ++k) {
      EXPECT_GT(R[k - 1] / R[k], 3.5) << "halving " << k;
      EXPECT_LT(R[k - 1] / R[k], 4.5) << "halving " << k;
    }
  }
}

// Velocity and acceleration sensors (rows on u̇ and ü; ü from the equation of motion). Their
// Gauss–Newton gradient is the exact derivative of the discrete cost (the sensitivities are
// stepped with the state, S̈ comes from the sensitivity equation), so it must match central
// differences of the cost (measured: 1.8e-6 beam, 5.9e-6 SCOLE), and the
// Taylor remainder must fall at second order. (The CVODES adjoint reference has no such outputs.)
namespace {
const char* kRatesBeam = R"(name: grad-rates-beam
beam: {length: 10, left: clamped, right: free, rho_A: 67, EI: 23000, zeta: 0.05, tip_mass: 30, tip_inertia: 5}
inputs: [{name: P, location: 10, signal: {type: haversine, amplitude: 10, t0: 0.05, width: 0.3}}]
sensors: [{name: a_tip, kind: acceleration, location: 10}, {name: v_mid, kind: velocity, location: 6}, {name: w, location: 8}]
simulation: {duration: 2, sample_interval: 0.01}
identification: {parameterization: physical, estimate: [rho_A, EI, zeta], initial: {rho_A: 60, EI: 20000, zeta: 0.08}, elements: 4}
)";
const char* kRatesScole = R"(name: grad-rates-scole
structure: scole
scole: {zeta: 0.01}
inputs:
  - {name: F_y, at: reflector, kind: force, direction: y, signal: {type: haversine, amplitude: 10, t0: 0, width: 0.5}}
  - {name: M_z, at: reflector, kind: moment, direction: z, signal: {type: haversine, amplitude: 200, t0: 0.2, width: 0.5}}
sensors:
  - {name: acc_tip_y, at: mast, kind: acceleration, location: 130, direction: y}
  - {name: acc_refl_x, at: reflector, kind: acceleration, direction: x}
  - {name: vel_mid_y, at: mast, kind: velocity, location: 65, direction: y}
  - {name: acc_shuttle_y, at: shuttle, kind: acceleration, direction: y}
simulation: {duration: 2, sample_interval: 0.01}
identification: {parameterization: physical, estimate: [EI, rho_A, GJ, m_reflector],
  initial: {EI: 3.8e7, rho_A: 0.09, GJ: 3.6e7, m_reflector: 11.5}, elements: 4}
)";

void check_rates(const char* yaml) {
  Case e = make_case(yaml, false);
  const VectorXd q = e.p->params->initial();
  VectorXd g_gn, g_cg;
  MatrixXd H;
  e.obj->gauss_newton(q, g_gn, H);
  e.obj->cost_and_gradient(q, g_cg);
  // Central differences in log q with one Richardson step (error O(η⁴)).
  VectorXd g_fd(q.size());
  for (int i = 0; i < q.size(); ++i) {
    auto D = [&](double eta) {
      VectorXd qp = q, qm = q;
      qp[i] *= std::exp(eta);
      qm[i] *= std::exp(-eta);
      return (e.obj->cost(qp) - e.obj->cost(qm)) / (2.0 * eta * q[i]);
    };
    g_fd[i] = (4.0 * D(5e-3) - D(1e-2)) / 3.0;
  }
  std::printf("  Gauss-Newton gradient vs FD %.2e\n", max_rel(g_gn, g_fd));
  for (int i = 0; i < q.size(); ++i)
    std::printf("    %-12s gauss-newton %+.10e  fd %+.10e\n", e.p->params->names()[static_cast<std::size_t>(i)].c_str(), g_gn[i],
                g_fd[i]);
  EXPECT_LT(max_rel(g_gn, g_fd), 1e-5);  // the bound the displacement-sensor tests hold it to
  EXPECT_EQ(max_rel(g_cg, g_gn), 0.0);
  const std::vector<double> R = test_support::taylor_remainders(*e.obj, q, 5);
  for (std::size_t k = 1; k < 5; ++k) {
    EXPECT_GT(R[k - 1] / R[k], 3.5) << "halving " << k;
    EXPECT_LT(R[k - 1] / R[k], 4.5) << "halving " << k;
  }
}
}  // namespace

TEST(Gradient, VelocityAndAccelerationSensorsBeam) { check_rates(kRatesBeam); }
TEST(Gradient, VelocityAndAccelerationSensorsScole) { check_rates(kRatesScole); }
