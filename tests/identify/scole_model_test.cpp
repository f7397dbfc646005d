// Ladder step 1 for SCOLE: the FE model of identify/scole_model.h — rigid-body modes and the
// rigid-body inertia of the whole configuration, frequency convergence rates per field, the
// clamped limit against closed-form beam and shaft frequencies, and (ladder step 2) the costate
// gradient against finite differences, the CVODES adjoint and a Taylor test.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdio>
#include <functional>
#include <random>

#include "test_support.h"
#include "scoleid/identify/fe/analytic_beam.h"
#include "scoleid/identify/time/banded_cholesky.h"
#include "scoleid/identify/inverse/cvodes_adjoint.h"
#include "scoleid/identify/fe/modal.h"
#include "scoleid/identify/run/problem.h"
#include "scoleid/identify/fe/scole_model.h"

using namespace scoleid::identify;
using test_support::Case;
using test_support::make_case;
using test_support::max_rel;
using Eigen::Vector3d;
using scoleid::io::ScoleSpec;

namespace {

// A configuration with every coupling switched on: root off the shuttle CM, products of
// inertia on both bodies, distinct bending stiffnesses.
ScoleSpec general_spec() {
  ScoleSpec s;
  s.mast_root = {1.5, -2.0, 3.0};
  s.shuttle.Ixy = 1200.0;
  s.shuttle.Ixz = -3000.0;
  s.shuttle.Iyz = 500.0;
  s.reflector.Ixy = 150.0;
  s.reflector.Ixz = -80.0;
  s.reflector.Iyz = 40.0;
  s.EI_roll = 3.5e7;
  return s;
}

AssembledModel operators(const ScoleFE& fe) { return assemble(fe.model, scole_coefficients(fe.spec)); }

Eigen::Matrix3d inertia(const scoleid::io::RigidBodySpec& b) {
  Eigen::Matrix3d I;
  I << b.Ixx, b.Ixy, b.Ixz, b.Ixy, b.Iyy, b.Iyz, b.Ixz, b.Iyz, b.Izz;
  return I;
}

// Kinetic-energy form of a rigid motion (translation a, rotation θ about the shuttle CM),
// computed from the configuration directly: 2T = Σ bodies m |a + θ × p|² + θᵀ I θ.
double rigid_inertia_form(const ScoleSpec& s, const Vector3d& a, const Vector3d& th) {
  const Vector3d r0(s.mast_root[0], s.mast_root[1], s.mast_root[2]);
  auto v2 = [&](const Vector3d& p) { return (a + th.cross(p)).squaredNorm(); };
  const double L = s.length;
  // Mast: the integrand is quadratic in s, so Simpson's rule is exact.
  const Vector3d p0 = r0, pm = r0 - 0.5 * L * Vector3d::UnitZ(), pL = r0 - L * Vector3d::UnitZ();
  double e = s.rho_A * L / 6.0 * (v2(p0) + 4.0 * v2(pm) + v2(pL)) + s.rho_I_psi * L * th[2] * th[2];
  // The section's bending rotary inertia ρI_ψ/2 per plane, when modelled.
  if (s.bending_rotary_inertia) e += 0.5 * s.rho_I_psi * L * (th[0] * th[0] + th[1] * th[1]);
  e += s.shuttle.mass * a.squaredNorm() + th.dot(inertia(s.shuttle) * th);
  e += s.reflector.mass * v2(pL + Vector3d(s.reflector_rx, s.reflector_ry, 0.0)) + th.dot(inertia(s.reflector) * th);
  for (double sk : s.actuator_locations) e += s.actuator_mass * v2(r0 - sk * Vector3d::UnitZ());
  return e;
}

// Flexible frequencies (the zero modes dropped), refined by inverse iteration on the sparse
// pencil (the dense solver's rounding, ~ε ω_max²/ω, would swamp the differences between fine
// meshes), with per mode: the share of strain energy in roll bending, pitch bending and torsion,
// and a priori indicators of the relative frequency error of each field's elements,
//   Hermite cubics (bending)  δ_b = h⁴/1440 · ω² ρA²/EI · ‖u‖²_ρA / ‖φ‖²_M     (rate 4)
//   linear (torsion)          δ_t = h²/24   · ω² ρI_ψ²/GJ · ‖ψ‖²_ρI / ‖φ‖²_M    (rate 2)
// (for a uniform clamped–free beam or shaft they are the classical (kh)⁴/1440 and (kh)²/24;
// in general, the interpolation-error energy with u'''' = ω² ρA/EI u and ψ'' = −ω² ρI_ψ/GJ ψ).
struct Modes {
  int zero = 0;
  std::vector<double> omega;
  std::vector<Eigen::Vector3d> share;  // roll, pitch, torsion
  std::vector<double> delta_bending, delta_torsion;
};

Modes modes(const ScoleFE& fe, double zero_threshold) {
  const AssembledModel a = operators(fe);
  const VectorXd c = scole_coefficients(fe.spec);
  Eigen::GeneralizedSelfAdjointEigenSolver<MatrixXd> es(MatrixXd(a.K), MatrixXd(a.M));
  Modes m;
  const double wmax = std::sqrt(es.eigenvalues().maxCoeff());
  const double h = fe.spec.length / fe.elements;
  const SparseMatrix& MA = fe.model.mass[0].matrix;  // unit-ρA term
  const SparseMatrix& MT = fe.model.mass[1].matrix;  // unit-ρI_ψ term
  const double EI = std::min(fe.spec.EI_roll, fe.spec.EI_pitch);
  for (int i = 0; i < es.eigenvalues().size(); ++i) {
    double lambda = std::max(0.0, es.eigenvalues()[i]);
    if (std::sqrt(lambda) < zero_threshold * wmax) {
      ++m.zero;
      continue;
    }
    VectorXd phi = es.eigenvectors().col(i);
    for (int it = 0; it < 2; ++it) {
      const SparseMatrix S = a.K - lambda * a.M;
      Eigen::SimplicialLDLT<SparseMatrix> ldlt(S);
      VectorXd x = ldlt.solve(VectorXd(a.M * phi));
      x /= std::sqrt(x.dot(a.M * x));
      lambda = x.dot(a.K * x);  // Rayleigh quotient, xᵀ M x = 1
      phi = x;
    }
    const double w = std::sqrt(lambda), mm = phi.dot(a.M * phi);
    Eigen::Vector3d e;
    for (int k = 0; k < 3; ++k) {
      const auto& t = fe.model.stiffness[static_cast<std::size_t>(k)];
      e[k] = c[t.coefficient] * phi.dot(t.matrix * phi);
    }
    m.omega.push_back(w);
    m.share.push_back(e / e.sum());
    const double rA = fe.spec.rho_A, rI = fe.spec.rho_I_psi;
    m.delta_bending.push_back(std::pow(h, 4) / 1440.0 * lambda * rA * rA / EI * phi.dot(MA * phi) / mm);
    m.delta_torsion.push_back(h * h / 24.0 * lambda * rI * rI / fe.spec.GJ * phi.dot(MT * phi) / mm);
  }
  return m;
}

const char* field_name(const Eigen::Vector3d& share) {
  int k = 0;
  share.maxCoeff(&k);
  return k == 0 ? "roll" : k == 1 ? "pitch" : "torsion";
}

}  // namespace

TEST(ScoleModel, RigidBodyMotionsSpanTheNullSpaceAndCarryTheWholeInertia) {
  const ScoleSpec s = general_spec();
  const ScoleFE fe = build_scole(s, 10, {}, {});
  const AssembledModel a = operators(fe);
  const MatrixXd K(a.K), M(a.M);
  EXPECT_LT((K - K.transpose()).cwiseAbs().maxCoeff(), 1e-14 * K.cwiseAbs().maxCoeff());
  EXPECT_LT((M - M.transpose()).cwiseAbs().maxCoeff(), 1e-14 * M.cwiseAbs().maxCoeff());
  EXPECT_EQ(Eigen::LLT<MatrixXd>(M).info(), Eigen::Success) << "M must be positive definite";

  // The six rigid motions: no strain energy, the root constraint reproduced at every station,
  // and the mass form equal to the configuration's rigid-body inertia.
  const Vector3d r0(s.mast_root[0], s.mast_root[1], s.mast_root[2]);
  const Vector3d r(s.reflector_rx, s.reflector_ry, 0.0);
  std::mt19937_64 rng(3);
  std::normal_distribution<double> N(0.0, 1.0);
  for (int k = 0; k < 8; ++k) {
    Vector3d t = Vector3d::Zero(), th = Vector3d::Zero();
    if (k < 3) t[k] = 1.0;
    else if (k < 6) th[k - 3] = 1e-2;
    else {
      t = Vector3d(N(rng), N(rng), N(rng));
      th = 1e-2 * Vector3d(N(rng), N(rng), N(rng));
    }
    const VectorXd u = fe.rigid_motion(t, th);
    EXPECT_LT((K * u).norm(), 1e-12 * K.norm() * u.norm()) << "rigid motion " << k;
    for (double st : {0.0, 7.3, 0.5 * s.length, s.length}) {
      const Vector3d p = r0 - st * Vector3d::UnitZ();
      EXPECT_LT((fe.mast_displacement(st) * u - (t + th.cross(p))).norm(), 1e-12) << "s = " << st;
      EXPECT_LT((fe.mast_rotation(st) * u - th).norm(), 1e-12) << "s = " << st;
    }
    const Vector3d pR = r0 - s.length * Vector3d::UnitZ() + r;
    EXPECT_LT((fe.reflector_displacement() * u - (t + th.cross(pR))).norm(), 1e-12);
    const double form = u.dot(M * u), exact = rigid_inertia_form(s, t, th);
    EXPECT_NEAR(form, exact, 1e-12 * exact) << "rigid motion " << k;
  }

  // K symmetric positive semi-definite, null space 6 + 2 per actuator (the proof masses ride
  // on springless sliders); everything else well above.
  const Modes m = modes(fe, 1e-7);
  const int nact = static_cast<int>(s.actuator_locations.size());
  EXPECT_EQ(m.zero, 6 + 2 * nact);
  Eigen::SelfAdjointEigenSolver<MatrixXd> ek(K);
  EXPECT_GT(ek.eigenvalues().minCoeff(), -1e-12 * ek.eigenvalues().maxCoeff());
  // The zero modes as the dense solver sees them: rounding of order √ε ω_max.
  const Eigen::GeneralizedSelfAdjointEigenSolver<MatrixXd> es(K, M, Eigen::EigenvaluesOnly);
  const double w_zero = std::sqrt(std::abs(es.eigenvalues()[m.zero - 1]));
  const double w_max = std::sqrt(es.eigenvalues().maxCoeff());
  std::printf("  %d zero modes, largest %.3e rad/s (omega_max %.3e); first flexible %.6f rad/s\n", m.zero, w_zero, w_max,
              m.omega[0]);
  EXPECT_LT(w_zero, 1e-4 * m.omega[0]);
  EXPECT_LT(w_zero, 1e-6 * w_max);
}

TEST(ScoleModel, FlexibleFrequenciesConvergeAtTheRateOfTheirField) {
  // Nominal configuration. Self-convergence (no closed form for the coupled structure):
  // rate = log2((ω_h − ω_h/2) / (ω_h/2 − ω_h/4)). The error indicators below are those of
  // Euler–Bernoulli bending, so the section's rotary inertia is left out.
  ScoleSpec s;
  s.bending_rotary_inertia = false;
  const std::vector<int> meshes = {5, 10, 20, 40, 80};
  const int shown = 14;
  std::vector<Modes> m;
  for (int ne : meshes) m.push_back(modes(build_scole(s, ne, {}, {}), 1e-7));
  std::printf("  mode  dominant (roll/pitch/tors)");
  for (int ne : meshes) std::printf("   ne=%-10d", ne);
  std::printf("  rates 5-10-20, 10-20-40, 20-40-80   d_b(20)   d_t(20)  (w20-w40)/w\n");
  for (int k = 0; k < shown; ++k) {
    const auto K = static_cast<std::size_t>(k);
    const Eigen::Vector3d sh = m[2].share[K];
    std::printf("  %4d  %-7s (%.2f/%.2f/%.2f)", k + 1, field_name(sh), sh[0], sh[1], sh[2]);
    for (const auto& mm : m) std::printf("  %14.9f", mm.omega[K]);
    std::vector<double> rate;
    for (std::size_t i = 0; i + 2 < m.size(); ++i)
      rate.push_back(std::log2((m[i].omega[K] - m[i + 1].omega[K]) / (m[i + 1].omega[K] - m[i + 2].omega[K])));
    for (double r : rate) std::printf("  %6.2f", r);
    const double db = m[2].delta_bending[K], dt = m[2].delta_torsion[K];
    const double observed = (m[2].omega[K] - m[3].omega[K]) / m[3].omega[K];
    std::printf("  %9.2e %9.2e %9.2e\n", db, dt, observed);
    // The rate of the field whose elements dominate the error (not necessarily the field holding
    // most of the strain energy: a twist that is nearly linear in s is exact on linear elements).
    const double r = rate[1];  // 10-20-40: every difference well above rounding
    if (dt > 10.0 * db) {
      EXPECT_NEAR(r, 2.0, 0.3) << "mode " << k + 1;
    } else if (db > 10.0 * dt) {
      EXPECT_NEAR(r, 4.0, 0.3) << "mode " << k + 1;
    } else {
      EXPECT_GT(r, 1.7) << "mode " << k + 1;
      EXPECT_LT(r, 4.3) << "mode " << k + 1;
    }
    // The indicators predict the error itself: ω_20 − ω_40 = (15/16 δ_b + 3/4 δ_t)(20) ω.
    EXPECT_NEAR(observed, 15.0 / 16.0 * db + 0.75 * dt, 0.25 * (15.0 / 16.0 * db + 0.75 * dt)) << "mode " << k + 1;
    // Conforming elements: frequencies converge from above.
    EXPECT_GT(m[0].omega[K], m[3].omega[K]) << "mode " << k + 1;
  }
}

TEST(ScoleModel, ClampedLimitMatchesTipBodyBeamAndShaft) {
  // Shuttle 1e9 times heavier (a clamped root to O(1e-9)), reflector CM at the tip (r = 0):
  // roll, pitch and torsion decouple. Bending: clamped beam with tip mass m4 and rotary inertia
  // I4xx (roll) or I4yy (pitch), analytic::beta_L_tip_mass. Torsion: ρI_ψ ψ_tt = GJ ψ_ss,
  // ψ(0) = 0, GJ ψ_s(L) = −I4zz ψ_tt(L); ψ = sin(β s/L) gives β tan β = ρI_ψ L / I4zz,
  // ω = (β/L) √(GJ/ρI_ψ). The proof masses stay: with springless sliders they load the mast only
  // axially, which is rigid.
  ScoleSpec s;
  s.shuttle.mass *= 1e9;
  s.shuttle.Ixx *= 1e9;
  s.shuttle.Iyy *= 1e9;
  s.shuttle.Izz *= 1e9;
  s.reflector_rx = s.reflector_ry = 0.0;
  s.EI_roll = 3.0e7;  // separates the roll and pitch families
  s.bending_rotary_inertia = false;  // the closed forms are Euler–Bernoulli's
  const double L = s.length;
  const int nb = 8, nt = 3;
  struct Ref {
    double omega;
    const char* field;
    int k;
  };
  std::vector<Ref> ref;
  const double rL = s.rho_A * L;
  const auto roll = analytic::beta_L_tip_mass(s.reflector.mass / rL, s.reflector.Ixx / (rL * L * L), nb);
  const auto pitch = analytic::beta_L_tip_mass(s.reflector.mass / rL, s.reflector.Iyy / (rL * L * L), nb);
  for (int k = 0; k < nb; ++k) {
    ref.push_back({analytic::omega(roll[static_cast<std::size_t>(k)], L, s.EI_roll, s.rho_A), "roll", k + 1});
    ref.push_back({analytic::omega(pitch[static_cast<std::size_t>(k)], L, s.EI_pitch, s.rho_A), "pitch", k + 1});
  }
  const double a = s.rho_I_psi * L / s.reflector.Izz;
  std::vector<double> beta_t;
  for (int k = 0; k < nt; ++k) {
    // β tan β = a has one root in (kπ, kπ + π/2); bisection on β sin β − a cos β.
    double lo = k * M_PI, hi = k * M_PI + 0.5 * M_PI;
    const auto f = [a](double b) { return b * std::sin(b) - a * std::cos(b); };
    for (int it = 0; it < 200; ++it) {
      const double mid = 0.5 * (lo + hi);
      (f(lo) * f(mid) <= 0 ? hi : lo) = mid;
    }
    beta_t.push_back(0.5 * (lo + hi));
    ref.push_back({beta_t.back() / L * std::sqrt(s.GJ / s.rho_I_psi), "torsion", k + 1});
  }
  std::sort(ref.begin(), ref.end(), [](const Ref& x, const Ref& y) { return x.omega < y.omega; });

  // Compare below the highest reference of the shortest family, where the list is complete.
  const double top = std::min({analytic::omega(roll.back(), L, s.EI_roll, s.rho_A),
                               analytic::omega(pitch.back(), L, s.EI_pitch, s.rho_A),
                               beta_t.back() / L * std::sqrt(s.GJ / s.rho_I_psi)});
  for (int ne : {20, 40}) {
    const Modes m = modes(build_scole(s, ne, {}, {}), 1e-7);
    const double h = L / ne;
    std::printf("  %d elements (%d zero modes)\n  %-8s %2s %16s %16s %12s %12s\n", ne, m.zero, "field", "k", "analytic",
                "FE", "rel.error", "bound");
    for (std::size_t i = 0; i < ref.size() && ref[i].omega <= top; ++i) {
      const double err = m.omega[i] / ref[i].omega - 1.0;
      // Discretisation error of a uniform member (the tip body only shifts the wavenumber):
      // Hermite cubics (kh)⁴/1440, k⁴ = ω² ρA/EI; linear elements (kh)²/24, k² = ω² ρI_ψ/GJ.
      const bool tors = std::string(ref[i].field) == "torsion";
      const double EI = std::string(ref[i].field) == "roll" ? s.EI_roll : s.EI_pitch;
      const double kh = tors ? ref[i].omega * std::sqrt(s.rho_I_psi / s.GJ) * h
                             : std::sqrt(ref[i].omega * std::sqrt(s.rho_A / EI)) * h;
      // 1e-9: the shuttle is 1e9 times heavier, not clamped.
      const double bound = (tors ? kh * kh / 24.0 : std::pow(kh, 4) / 1440.0) * 1.05 + 1e-8;
      std::printf("  %-8s %2d %16.9f %16.9f %12.3e %12.3e\n", ref[i].field, ref[i].k, ref[i].omega, m.omega[i], err, bound);
      EXPECT_LT(std::abs(err), bound) << ref[i].field << " " << ref[i].k << ", " << ne << " elements";
      EXPECT_GT(err, -1e-9) << ref[i].field << " " << ref[i].k << ", " << ne << " elements";
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Gradients (ladder step 2) on a short horizon and a coarse mesh, every input and sensor kind
// the SCOLE model represents.

namespace {

const char* kScoleInputs = R"(inputs:
  - {name: F_x, at: reflector, kind: force, direction: x, signal: {type: haversine, amplitude: 10, t0: 0, width: 0.6}}
  - {name: F_y, at: reflector, kind: force, direction: [0.3, 1, 0.2], signal: {type: haversine, amplitude: 10, t0: 0.2, width: 0.6}}
  - {name: M_z, at: reflector, kind: moment, direction: z, signal: {type: haversine, amplitude: 200, t0: 0, width: 0.5}}
  - {name: M_roll, at: shuttle, kind: moment, direction: x, signal: {type: pulse, amplitude: 500, t0: 0.1, width: 0.4}}
  - {name: A1, at: actuator1, kind: force, direction: [1, 1, 0], signal: {type: haversine, amplitude: 2, t0: 0.3, width: 0.4}}
  - {name: P_mast, at: mast, location: 50, kind: force, direction: y, signal: {type: haversine, amplitude: 5, t0: 0.4, width: 0.5}}
sensors:
  - {name: roll_tip, at: mast, kind: displacement, location: 130, direction: y}
  - {name: pitch_mid, at: mast, kind: displacement, location: 71, direction: x}
  - {name: yaw_tip, at: reflector, kind: rotation, direction: z}
  - {name: yaw_mid, at: mast, kind: rotation, location: 65, direction: z}
  - {name: los_x, at: reflector, kind: line_of_sight, direction: x}
  - {name: refl_x, at: reflector, kind: displacement, direction: x}
simulation: {duration: 2, sample_interval: 0.01}
)";

std::string scole_yaml(const char* name, const char* identification) {
  return std::string("name: ") + name + "\nstructure: scole\nscole: {zeta: 0.01}\n" + kScoleInputs + identification;
}

// The reflector's mass, a quantity of SCOLE's parameter table like any other.
const char* kReflectorId =
    "identification: {parameterization: physical, estimate: [m_reflector, EI, rho_A],\n"
    "  initial: {m_reflector: 11.5, EI: 3.8e7, rho_A: 0.09}, elements: 4}\n";
const char* kPaperId = "identification: {parameterization: paper, estimate: [q1, q2], initial: {rho_A: 0.085, EI: 3.6e7}, elements: 4}\n";
const char* kPhysicalId =
    "identification: {parameterization: physical, estimate: [EI_roll, EI_pitch, rho_A, rho_I_psi, GJ, zeta],\n"
    "  initial: {EI_roll: 3.6e7, EI_pitch: 4.3e7, rho_A: 0.085, rho_I_psi: 1.1, GJ: 3.5e7, zeta: 0.015}, elements: 4}\n";

// richardson_gradient (test_support.h) at its relative step 1e-2 keeps rounding small for
// parameters that move J only slightly (ζ over a 2 s horizon changes J by 1e-5 relative per unit
// relative change).
void check_gradient(const std::string& yaml, double refine = 4.0) {
  // The costate and sensitivity gradients are optimise-then-discretise: they differ from the
  // derivative of the discrete cost by the time error, O(h³). At the automatic step that gap is
  // printed; at a quarter of it the three derivatives must agree to 1e-5.
  Case a = make_case(yaml, false);
  const VectorXd q = a.p->params->initial();
  const double h = a.p->objective_options.solver.step;
  {
    VectorXd g_adj, g_gn;
    MatrixXd H;
    a.obj->cost_and_gradient(q, g_adj);
    a.obj->gauss_newton(q, g_gn, H);
    std::printf("  esdirk, automatic step %.3e (%d DOFs): costate vs Gauss-Newton %.2e\n", h, a.p->model().ndof,
                max_rel(g_adj, g_gn));
  }
  Case e = make_case(yaml, false, h / refine);
  VectorXd g_adj, g_gn;
  MatrixXd H;
  e.obj->cost_and_gradient(q, g_adj);
  e.obj->gauss_newton(q, g_gn, H);
  const VectorXd g_fd = test_support::richardson_gradient(*e.obj, q);
  std::printf("  esdirk, step %.3e: costate vs FD %.2e, Gauss-Newton vs FD %.2e, costate vs Gauss-Newton %.2e\n",
              h / refine, max_rel(g_adj, g_fd), max_rel(g_gn, g_fd), max_rel(g_adj, g_gn));
  for (int i = 0; i < q.size(); ++i)
    std::printf("    %-9s costate %+.10e  gauss-newton %+.10e  fd %+.10e\n",
                e.p->params->names()[static_cast<std::size_t>(i)].c_str(), g_adj[i], g_gn[i], g_fd[i]);
  EXPECT_LT(max_rel(g_adj, g_fd), 1e-5);
  EXPECT_LT(max_rel(g_gn, g_fd), 1e-5);
  // Adaptive BDF at rtol 1e-10: costate vs the CVODES adjoint (CVodeF/CVodeB).
  test_support::expect_costate_matches_cvodes(yaml, q);
}

}  // namespace

TEST(ScoleGradient, PaperParameters) { check_gradient(scole_yaml("grad-scole-paper", kPaperId)); }
TEST(ScoleGradient, PhysicalParameters) { check_gradient(scole_yaml("grad-scole-physical", kPhysicalId)); }
TEST(ScoleGradient, ReflectorMass) { check_gradient(scole_yaml("grad-scole-reflector", kReflectorId)); }
// The proof-mass actuators' centering spring and damper (docs/theory.md §3.7), with ζ.
TEST(ScoleGradient, ActuatorSpringAndDamper) {
  check_gradient(std::string("name: grad-scole-actuator\nstructure: scole\n"
                             "scole: {zeta: 0.01, actuator_stiffness: 8, actuator_damping: 0.3}\n") +
                 kScoleInputs +
                 "identification: {parameterization: physical, estimate: [k_actuator, c_actuator, zeta, EI],\n"
                 "  initial: {k_actuator: 9, c_actuator: 0.25, zeta: 0.012, EI: 3.8e7}, elements: 4}\n");
}
// ρI_ψ and ζ with the section's bending rotary inertia off (the Euler–Bernoulli mast).
TEST(ScoleGradient, EulerBernoulliMast) {
  // Without the rotary inertia ρI_ψ is seen through torsion alone and its gradient component is
  // 4e-4 of ρA's; the costate's time error in it is 1.4e-4 relative at the automatic step, 2.2e-5
  // at a quarter of it (the stiff torsion mode, ω h ≈ 0.6, is pre-asymptotic): checked at an
  // eighth.
  check_gradient(std::string("name: grad-scole-eb\nstructure: scole\nscole: {zeta: 0.01, bending_rotary_inertia: false}\n") +
                 kScoleInputs +
                 "identification: {parameterization: physical, estimate: [rho_I_psi, zeta, rho_A],\n"
                 "  initial: {rho_I_psi: 1.1, zeta: 0.015, rho_A: 0.085}, elements: 4}\n",
                 8.0);
}

TEST(ScoleGradient, TaylorRemainderFallsAtSecondOrder) {
  // R(ε) = |J(q ∘ exp(ε d)) − J(q) − ε ∇J·(q ∘ d)| for a random direction d in log q.
  for (const char* id : {kPaperId, kPhysicalId, kReflectorId}) {
    Case e = make_case(scole_yaml("taylor", id), false);
    const std::vector<double> R = test_support::taylor_remainders(*e.obj, e.p->params->initial(), 11);
    test_support::expect_second_order(R);
  }
}

TEST(ScoleModel, NewtonMatrixBandwidthDoesNotGrowWithTheMesh) {
  // DOF order (nodes root to tip with the proof masses beside their node, the shuttle's six DOFs
  // last) keeps M + γD + γ²K banded with a six-row border, so every time-step solve is linear in
  // the number of elements. A factorisation with that shape reproduces a dense solve.
  std::vector<BandedCholesky::Shape> b;
  for (int ne : {10, 40, 160}) {
    ScoleSpec spec;
    spec.mast_root = {1.5, -2.0, 3.0};  // every coupling of the root
    const ScoleFE fe = build_scole(spec, ne, {}, {});
    const AssembledModel a = operators(fe);
    const SparseMatrix S = a.M + 0.01 * a.D + 1e-4 * a.K;
    b.push_back(BandedCholesky::shape(S));
    std::printf("  %3d elements: %4d DOFs, half bandwidth %d, border %d\n", ne, fe.model.ndof, b.back().band,
                b.back().border);
    BandedCholesky c;
    c.resize(fe.model.ndof, b.back());
    c.assign(S);
    ASSERT_TRUE(c.factorize());
    const VectorXd r = VectorXd::LinSpaced(fe.model.ndof, -1.0, 2.0);
    VectorXd x = r;
    c.solve_in_place(x.data());
    const VectorXd ref = MatrixXd(S).ldlt().solve(r);
    EXPECT_LT((x - ref).norm(), 1e-9 * ref.norm()) << ne << " elements";
    // Several right-hand sides in one sweep (the sensitivities' stage solves): each column is bit
    // for bit its one-column solve, whatever the number of columns.
    const MatrixXd R = MatrixXd::Random(fe.model.ndof, 5);
    MatrixXd X = R;
    c.solve_in_place(X.data(), 5, X.rows());
    const MatrixXd Xref = MatrixXd(S).ldlt().solve(R);
    EXPECT_LT((X - Xref).norm(), 1e-9 * Xref.norm()) << ne << " elements, 5 columns";
    for (int j = 0; j < 5; ++j) {
      VectorXd xj = R.col(j);
      c.solve_in_place(xj.data());
      EXPECT_TRUE(xj == X.col(j)) << ne << " elements, column " << j;
    }
  }
  EXPECT_EQ(b[0].band, b[1].band);
  EXPECT_EQ(b[1].band, b[2].band);
  EXPECT_LE(b[0].band, 12);
  EXPECT_LE(b[2].border, 6);
}
