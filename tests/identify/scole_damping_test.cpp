// SCOLE's damping and actuator physics in the FE model (docs/theory.md §3.3, §3.7):
//  - the damping operator annihilates every rigid motion (the mast is damped relative to the
//    shuttle: rigid motion is not damped, momentum is not dissipated);
//  - torsion: the first clamped–free mode of the bare mast has damping ratio ζ;
//  - bending: with the square-root law every mode of the clamped bare mast has a ratio of order ζ;
//  - a proof-mass actuator on an effectively fixed base: the steady stroke amplitude under a
//    commanded sine is the single-DOF F / |k − mω² + icω| (F / (cω) at resonance), from the
//    FE's own frequency response (K − ω²M + iωD) X = b F.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>

#include "scoleid/identify/fe/modal.h"
#include "scoleid/identify/fe/scole_model.h"

using namespace scoleid::identify;
using scoleid::io::ScoleSpec;

namespace {
// Everything but the proof masses a million times heavier (masses and stiffnesses scaled
// together: the structure's frequencies are unchanged).
ScoleSpec heavy_base(double k, double c) {
  ScoleSpec s;
  const double g = 1e6;
  s.rho_A *= g;
  s.EI_roll *= g;
  s.EI_pitch *= g;
  s.GJ *= g;
  s.rho_I_psi *= g;
  for (auto* b : {&s.shuttle, &s.reflector}) {
    b->mass *= g;
    b->Ixx *= g;
    b->Iyy *= g;
    b->Izz *= g;
  }
  s.actuator_stiffness = k;
  s.actuator_damping = c;
  return s;
}
}  // namespace

TEST(ScoleDamping, RigidMotionsAreNotDamped) {
  ScoleSpec s;
  s.mast_root = {1.5, -2.0, 3.0};
  s.zeta = 0.02;
  s.actuator_damping = 0.5;
  s.actuator_stiffness = 3.0;
  const ScoleFE fe = build_scole(s, 12, {}, {});
  const AssembledModel a = assemble(fe.model, scole_coefficients(s));
  const MatrixXd D(a.D), K(a.K);
  EXPECT_LT((D - D.transpose()).cwiseAbs().maxCoeff(), 1e-13 * D.cwiseAbs().maxCoeff());
  Eigen::SelfAdjointEigenSolver<MatrixXd> ed(D);
  EXPECT_GT(ed.eigenvalues().minCoeff(), -1e-12 * ed.eigenvalues().maxCoeff()) << "D must be positive semidefinite";
  for (int k = 0; k < 6; ++k) {
    Eigen::Vector3d t = Eigen::Vector3d::Zero(), th = Eigen::Vector3d::Zero();
    (k < 3 ? t[k] : th[k - 3]) = 1.0;
    const VectorXd u = fe.rigid_motion(t, th);
    EXPECT_LT((D * u).norm(), 1e-12 * D.norm() * u.norm()) << "rigid motion " << k;
    EXPECT_LT((K * u).norm(), 1e-12 * K.norm() * u.norm()) << "rigid motion " << k;
  }
}

TEST(ScoleDamping, BareClampedMastTorsionRatioIsZeta) {
  // Shuttle 1e9 times heavier (clamped root), reflector and proof masses negligible: the bare
  // clamped–free mast. Torsion c_ψ = 2ζ√(ρI_ψ GJ)·2L/π gives its first mode exactly ζ (linear
  // elements: to O(h²)); square-root bending damping gives each bending mode
  // ζ_k = ζ √(EI/ρA) ∫w'² / (ω_k ∫w²), of order ζ (exactly ζ only for pinned ends).
  ScoleSpec s;
  s.zeta = 0.01;
  s.shuttle = {6366.0e9, 905443.0e9, 6789100.0e9, 7086601.0e9, 0, 0, 0};
  s.reflector = {1e-9, 1e-9, 1e-9, 2e-9, 0, 0, 0};
  s.actuator_mass = 1e-9;
  s.actuator_stiffness = 1.0;  // keeps the proof masses' modes away from zero
  s.EI_roll = 3.0e7;           // separates the planes
  const ScoleFE fe = build_scole(s, 80, {}, {});
  const AssembledModel a = assemble(fe.model, scole_coefficients(s));
  const auto modes = damped_modes(MatrixXd(a.M), MatrixXd(a.D), MatrixXd(a.K));
  const double L = s.length, w_t = M_PI / (2 * L) * std::sqrt(s.GJ / s.rho_I_psi);
  bool found = false;
  for (const auto& m : modes) {
    if (std::abs(m.omega / w_t - 1.0) < 1e-3) {
      found = true;
      std::printf("  first torsion mode %.6f rad/s (closed form %.6f): damping ratio %.8f, zeta %.8f\n", m.omega, w_t,
                  m.zeta, s.zeta);
      EXPECT_NEAR(m.zeta / s.zeta, 1.0, 1e-3);
    }
  }
  EXPECT_TRUE(found);
  int shown = 0;
  for (const auto& m : modes)
    if (m.omega < 60.0 && m.omega > 0.1 && shown++ < 8) {
      std::printf("  mode %.4f rad/s: damping ratio %.6f (%.3f zeta)\n", m.omega, m.zeta, m.zeta / s.zeta);
      EXPECT_GT(m.zeta, 0.3 * s.zeta);
      EXPECT_LT(m.zeta, 1.5 * s.zeta);
    }
}

TEST(ScoleDamping, ActuatorOnAFixedBaseIsASingleDofOscillator) {
  const double m = 0.2, w = 2 * M_PI * 3.0, k = m * w * w, c = 2 * 0.05 * m * w, F = 0.1;
  const ScoleSpec s = heavy_base(k, c);
  scoleid::io::InputSpec in;
  in.name = "a1x";
  in.at = scoleid::io::Site::Actuator1;
  in.kind = scoleid::io::InputKind::Force;
  in.direction = {1.0, 0.0, 0.0};
  const ScoleFE fe = build_scole(s, 10, {in}, {});
  const AssembledModel a = assemble(fe.model, scole_coefficients(s));
  const Eigen::RowVectorXd stroke = [&] {
    Eigen::RowVectorXd r = -fe.mast_displacement(s.actuator_locations[0]).row(0);
    r[fe.proof_mass_dof(0, 0)] += 1.0;
    return r;
  }();
  for (double ratio : {1.0, 1.5, 0.6}) {
    const double om = ratio * w;
    const Eigen::MatrixXcd S = MatrixXd(a.K).cast<std::complex<double>>() - om * om * MatrixXd(a.M).cast<std::complex<double>>() +
                               std::complex<double>(0.0, om) * MatrixXd(a.D).cast<std::complex<double>>();
    const Eigen::VectorXcd X = S.partialPivLu().solve((F * fe.model.inputs[0].vector).cast<std::complex<double>>());
    const double got = std::abs((stroke.cast<std::complex<double>>() * X)(0));
    const double expected = F / std::hypot(k - m * om * om, c * om);
    std::printf("  %.2f x resonance: stroke amplitude %.8e ft, single-DOF %.8e ft (%+.2e)\n", ratio, got, expected,
                got / expected - 1.0);
    EXPECT_NEAR(got / expected, 1.0, 1e-5);
  }
}
