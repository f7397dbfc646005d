// The nonlinear SCOLE model (identify/fe/scole_nonlinear.h, docs/theory.md §3.8): the rotation
// vector's kinematics against finite differences of the exponential; at rest its linearisation
// is the linear model (mass, stiffness, damping, loads); the undamped, unforced spinning and
// vibrating model conserves energy, linear and angular momentum; small pulses give the linear
// model's response up to a difference of second order in the amplitude; the 20° slew reaches the
// rigid-body angle, where the linear model does not follow.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <random>
#include <utility>

#include "scoleid/identify/door/scenario_door.h"
#include "scoleid/identify/fe/rotation_vector.h"
#include "scoleid/identify/fe/scole_nonlinear.h"
#include "scoleid/identify/fe/turned_arm.h"
#include "scoleid/identify/inverse/cvodes_adjoint.h"
#include "scoleid/identify/inverse/nonlinear_objective.h"
#include "scoleid/identify/run/identify_run.h"
#include "scoleid/identify/run/problem.h"
#include "scoleid/identify/time/nonlinear_forward.h"
#include "scoleid/io/error.h"
#include "scoleid/io/scenario.h"
#include "test_support.h"

using namespace scoleid::identify;
using Eigen::Matrix3d;
using Eigen::Vector3d;

namespace {

struct Model {
  scoleid::io::Scenario sc;
  ScoleFE fe;
  std::unique_ptr<ScoleNonlinear> nl;
};

Model make_model(scoleid::io::Scenario sc, int elements) {
  Model m;
  m.sc = std::move(sc);
  m.fe = build_scole(m.sc.scole, elements, m.sc.inputs, m.sc.sensors);
  m.nl = std::make_unique<ScoleNonlinear>(m.fe, m.sc.inputs, m.sc.sensors);
  return m;
}

// A deflection and a deflection rate with normal random entries, each scaled to a largest entry of 1.
std::pair<VectorXd, VectorXd> random_deflection(int ne, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> N(0.0, 1.0);
  VectorXd e0(ne), v0(ne);
  for (int i = 0; i < ne; ++i) {
    e0[i] = N(rng);
    v0[i] = N(rng);
  }
  return {e0 / e0.cwiseAbs().maxCoeff(), v0 / v0.cwiseAbs().maxCoeff()};
}

// For ε = 0.08, 0.04, 0.02, 0.01, at(ε) = {an exact change, the model's difference to it}: prints
// them and the order at which the difference falls, and expects at least min_order.
void expect_order(double min_order, const std::function<std::pair<double, double>(double)>& at) {
  double prev = 0.0;
  for (double eps : {0.08, 0.04, 0.02, 0.01}) {
    const auto r = at(eps);
    const double diff = r.second;
    std::printf("  eps %.2f  exact change %+.6e  difference %.3e", eps, r.first, diff);
    if (prev > 0) {
      std::printf("  (order %.2f)", std::log2(prev / diff));
      EXPECT_GT(std::log2(prev / diff), min_order) << "eps " << eps;
    }
    std::printf("\n");
    prev = diff;
  }
}

scoleid::io::Scenario builtin(const std::string& name) {
  return scoleid::io::parse_scenario(scoleid::io::builtin_scenario_yaml(name), name);
}

std::vector<scoleid::io::Signal> signals_of(const scoleid::io::Scenario& sc, double scale = 1.0) {
  std::vector<scoleid::io::Signal> s;
  for (const auto& in : sc.inputs) {
    auto terms = in.signal.terms();
    for (auto& t : terms) t.amplitude *= scale;
    s.emplace_back(terms);
  }
  return s;
}

std::vector<double> sample_times(double duration, double dt) {
  std::vector<double> t;
  const int n = static_cast<int>(std::lround(duration / dt));
  for (int k = 0; k <= n; ++k) t.push_back(k * dt);
  return t;
}

// The linear model's response by the product's own path (the same ESDIRK table at the same fixed
// step, so the two discretisations differ only by the model) at the true values.
MatrixXd linear_response(scoleid::io::Scenario sc, int elements, double scale, double step) {
  sc.identification.elements = elements;
  sc.identification.time_step = step;
  for (auto& in : sc.inputs) {
    auto terms = in.signal.terms();
    for (auto& t : terms) t.amplitude *= scale;
    in.signal = scoleid::io::Signal(terms);
  }
  auto p = make_problem(sc, std::nullopt);
  const auto& names = p->params->names();
  VectorXd q(static_cast<Eigen::Index>(names.size()));
  for (std::size_t i = 0; i < names.size(); ++i) q[static_cast<Eigen::Index>(i)] = p->true_values.at(names[i]);
  Objective obj(p->model(), *p->params, p->signals, p->data, p->objective_options);
  return obj.predict(q);
}

double relative_rms(const Eigen::VectorXd& a, const Eigen::VectorXd& b) { return (a - b).norm() / b.norm(); }

}  // namespace

TEST(RotationVector, KinematicsMatchTheExponential) {
  for (const Vector3d& phi : {Vector3d(0.3, -0.2, 0.5), Vector3d(1e-6, 2e-6, -1e-6), Vector3d(0.0, 2.5, 0.4)}) {
    const Matrix3d R = rotation_matrix(phi);
    EXPECT_LT((R.transpose() * R - Matrix3d::Identity()).norm(), 1e-14);
    const double angle = phi.norm();
    const Matrix3d ref = Eigen::AngleAxisd(angle, angle > 0 ? Vector3d(phi / angle) : Vector3d::UnitX()).toRotationMatrix();
    EXPECT_LT((R - ref).norm(), 1e-14);
    EXPECT_LT((right_jacobian(phi) * right_jacobian_inverse(phi) - Matrix3d::Identity()).norm(), 1e-13);
    // Rᵀ(φ) R(φ + δ) = exp([J_r δ]×) + O(δ²): central differences of the body increment.
    for (int k = 0; k < 3; ++k) {
      const double d = 1e-6;
      const Matrix3d A = R.transpose() * rotation_matrix(phi + d * Vector3d::Unit(k));
      const Matrix3d B = R.transpose() * rotation_matrix(phi - d * Vector3d::Unit(k));
      const Matrix3d S = (A - B) / (2 * d);
      const Vector3d w(S(2, 1), S(0, 2), S(1, 0));
      EXPECT_LT((w - right_jacobian(phi).col(k)).norm(), 1e-9) << "phi " << phi.transpose() << " k " << k;
    }
  }
}

TEST(ScoleNonlinear, AtRestItsLinearisationIsTheLinearModel) {
  // Every coupling on: root off the CM, products of inertia, actuators with springs and dampers.
  auto sc = builtin("paper-scole-1");
  sc.scole.mast_root = {1.5, -2.0, 3.0};
  sc.scole.shuttle.Ixy = 1200.0;
  sc.scole.shuttle.Ixz = -3000.0;
  sc.scole.reflector.Ixy = 150.0;
  sc.scole.reflector.Iyz = 40.0;
  sc.scole.actuator_stiffness = 30.0;
  sc.scole.actuator_damping = 2.0;
  sc.scole.zeta = 0.01;
  const Model m = make_model(sc, 6);
  const VectorXd c = scole_coefficients(m.fe.spec);
  const AssembledModel lin = assemble(m.fe.model, c);
  const auto dyn = m.nl->at(c);
  const MatrixXd& G = m.nl->linear_map();
  const int ne = m.nl->elastic();
  const MatrixXd Mref = G.transpose() * MatrixXd(lin.M) * G;
  const MatrixXd M0 = dyn.mass(VectorXd::Zero(ne));
  std::printf("  |M(0) - G'M G| / |M| = %.3e\n", (M0 - Mref).norm() / Mref.norm());
  EXPECT_LT((M0 - Mref).norm(), 1e-12 * Mref.norm());
  // K and D: the elastic blocks, and nothing on the rigid coordinates.
  const MatrixXd Kref = G.transpose() * MatrixXd(lin.K) * G, Dref = G.transpose() * MatrixXd(lin.D) * G;
  EXPECT_LT(Kref.topRows(6).norm(), 1e-9 * Kref.norm());
  EXPECT_LT(Dref.topRows(6).norm(), 1e-9 * Dref.norm());
  // The internal force's derivative at rest is [0; 0; D ė + K e] (the inertial terms are
  // quadratic in the speeds), checked by directional differences.
  std::mt19937_64 rng(5);
  std::normal_distribution<double> N(0.0, 1.0);
  VectorXd e(ne), u(6 + ne);
  for (int i = 0; i < ne; ++i) e[i] = 1e-3 * N(rng);
  for (int i = 0; i < 6 + ne; ++i) u[i] = 1e-3 * N(rng);
  const double h = 1e-4;
  const VectorXd de = (dyn.internal(VectorXd::Zero(6 + ne), h * e) - dyn.internal(VectorXd::Zero(6 + ne), -h * e)) / (2 * h);
  const VectorXd du = (dyn.internal(h * u, VectorXd::Zero(ne)) - dyn.internal(-h * u, VectorXd::Zero(ne))) / (2 * h);
  EXPECT_LT((de - Kref.rightCols(ne) * e).norm(), 1e-9 * (Kref.rightCols(ne) * e).norm());
  EXPECT_LT((du - Dref * u).norm(), 1e-9 * (Dref * u).norm() + 1e-12);
  // Loads at rest: Gᵀ b.
  for (int i = 0; i < m.nl->inputs(); ++i) {
    VectorXd f = VectorXd::Zero(m.nl->inputs());
    f[i] = 1.0;
    const VectorXd ref = G.transpose() * lin.loads[static_cast<std::size_t>(i)];
    EXPECT_LT((dyn.load(f, VectorXd::Zero(ne)) - ref).norm(), 1e-12 * ref.norm()) << "input " << i;
  }
}

namespace {
// The section's rotation on the FE's own fields, exactly: the tangent t = t⊥ + a √(1 − |t⊥|²) with t⊥ = θ × a (θ the rotation rows: the slopes
// turned by 90°, a = −ẑ the axis), the section's rotation R = A Z with A the shortest rotation
// taking a to t and Z the twist θ_z about ẑ.
Matrix3d section_rotation(const ScoleFE& fe, int ne, const VectorXd& e, double s) {
  const Vector3d a(0, 0, -1);
  const Vector3d th = fe.mast_rotation(s).leftCols(ne) * e;
  const Vector3d tp = Vector3d(th[0], th[1], 0.0).cross(a);
  const Vector3d t = tp + a * std::sqrt(1.0 - tp.squaredNorm());
  const Vector3d axt = a.cross(t);
  Matrix3d A = Matrix3d::Identity();
  if (axt.norm() > 0.0) {
    const Vector3d n = axt.normalized();
    const double phi = std::atan2(axt.norm(), a.dot(t));
    A += std::sin(phi) * skew(n) + (1.0 - std::cos(phi)) * skew(n) * skew(n);
  }
  return A * Eigen::AngleAxisd(th[2], Vector3d::UnitZ()).toRotationMatrix();
}

// The Kirchhoff rod's exact strain energy ½ ∫ κᵀ C κ ds of the mast's deflection e: κ = axial(Rᵀ R')
// with R' by a fourth-order difference, integrated by 4 × 5 Gauss points per element.
double exact_strain_energy(const ScoleFE& fe, int ne, const VectorXd& e) {
  const auto& sc = fe.spec;
  const double h = sc.length / fe.elements;
  auto rotation = [&](double s) { return section_rotation(fe, ne, e, s); };
  const double xg[5] = {0.0, -0.5384693101056831, 0.5384693101056831, -0.9061798459386640, 0.9061798459386640};
  const double wg[5] = {0.5688888888888889, 0.4786286704993665, 0.4786286704993665, 0.2369268850561891, 0.2369268850561891};
  const Vector3d C(sc.EI_roll, sc.EI_pitch, sc.GJ);
  double W = 0.0;
  for (int el = 0; el < fe.elements; ++el)
    for (int sub = 0; sub < 4; ++sub)
      for (int q = 0; q < 5; ++q) {
        const double hs = h / 4, s = el * h + (sub + 0.5 + 0.5 * xg[q]) * hs, d = 1e-3 * hs;
        const Matrix3d Rd = (rotation(s - 2 * d) - 8.0 * rotation(s - d) + 8.0 * rotation(s + d) - rotation(s + 2 * d)) / (12 * d);
        const Matrix3d K = rotation(s).transpose() * Rd;
        const Vector3d kappa(0.5 * (K(2, 1) - K(1, 2)), 0.5 * (K(0, 2) - K(2, 0)), 0.5 * (K(1, 0) - K(0, 1)));
        W += 0.5 * wg[q] * hs * 0.5 * kappa.dot(C.cwiseProduct(kappa));
      }
  return W;
}
}  // namespace

TEST(ScoleNonlinear, TheStrainEnergyIsTheRodsToFourthOrderInTheDeflection) {
  // The model's strain energy ½ eᵀ K e + W₃ + W₄ against the exact energy of the inextensible,
  // unshearable rod on the same fields, for a random deflection ±ε e₀: the part of their difference
  // odd in ε is of fifth order (W₅ is not in the model), the even part of sixth. The quadratic
  // energy alone leaves the odd part at third order (W₃) and the even at fourth (W₄). Anisotropic
  // stiffnesses, so that every term of W₃ and W₄ counts.
  auto sc = builtin("paper-scole-1");
  sc.scole.EI_pitch = 0.8 * sc.scole.EI_roll;
  sc.scole.GJ = 0.6 * sc.scole.EI_roll;
  sc.scole.actuator_stiffness = 0.0;  // the strokes' springs are not the rod's
  const Model m = make_model(sc, 4);
  const int ne = m.nl->elastic();
  const VectorXd c = scole_coefficients(m.fe.spec);
  const auto dyn = m.nl->at(c);
  MatrixXd K = MatrixXd::Zero(m.fe.model.ndof, m.fe.model.ndof);
  for (const auto& t : m.fe.model.stiffness) K += c[t.coefficient] * MatrixXd(t.matrix);
  std::mt19937_64 rng(5);
  std::normal_distribution<double> N(0.0, 1.0);
  VectorXd e0(ne);
  for (int i = 0; i < ne; ++i) e0[i] = N(rng);
  // Scaled so that the largest slope or twist at a node is 1 (ε is about the largest rotation).
  e0 /= e0.cwiseAbs().maxCoeff();
  // Relative odd and even parts of (model − exact) and of (quadratic − exact) at ε.
  auto parts = [&](double eps) {
    double model[2], quad[2], exact[2];
    for (int k = 0; k < 2; ++k) {
      const VectorXd e = (k == 0 ? eps : -eps) * e0;
      VectorXd y = VectorXd::Zero(m.nl->state_size());
      y.segment(6, ne) = e;
      exact[k] = exact_strain_energy(m.fe, ne, e);
      model[k] = dyn.energy(y.data());
      quad[k] = 0.5 * e.dot(K.topLeftCorner(ne, ne) * e);
    }
    const double E = 0.5 * (exact[0] + exact[1]);
    auto odd = [&](const double* v) { return std::abs((v[0] - v[1]) - (exact[0] - exact[1])) / (2 * E); };
    auto even = [&](const double* v) { return std::abs((v[0] + v[1]) - (exact[0] + exact[1])) / (2 * E); };
    return std::array<double, 4>{odd(model), even(model), odd(quad), even(quad)};
  };
  std::array<double, 4> prev{};
  for (double eps : {0.04, 0.02, 0.01}) {
    const auto p = parts(eps);
    std::printf("  eps %.2f  relative difference, odd / even part: model %.2e / %.2e, quadratic energy alone %.2e / %.2e", eps,
                p[0], p[1], p[2], p[3]);
    if (prev[0] > 0) {
      std::array<double, 4> order{};
      for (std::size_t k = 0; k < 4; ++k) order[k] = std::log2(prev[k] / p[k]) + 2.0;  // +2: relative to ½ eᵀ K e
      std::printf("  (orders %.2f / %.2f, %.2f / %.2f)", order[0], order[1], order[2], order[3]);
      EXPECT_GT(order[0], 4.6);
      EXPECT_GT(order[1], 5.6);
      EXPECT_LT(order[2], 3.4);  // the check sees what W₃ and W₄ add
      EXPECT_LT(order[3], 4.4);
    }
    std::printf("\n");
    prev = p;
  }
}

// paper-scole-1 on 4 elements with a general reflector inertia (products of inertia, I_zz not
// I_xx + I_yy) and every other mass negligible, the stiffnesses zero: the reflector's own kinetic
// energy, for the tests of its turning inertia and angular velocity.
struct ReflectorOnly {
  Model m;
  ScoleNonlinear::Dynamics dyn;
  Matrix3d J;
  int ne;
  ReflectorOnly() : m(make_model(scenario(), 4)), dyn(m.nl->at(coefficients(m))), ne(m.nl->elastic()) {
    const auto& I = m.sc.scole.reflector;
    J << I.Ixx, I.Ixy, I.Ixz, I.Ixy, I.Iyy, I.Iyz, I.Ixz, I.Iyz, I.Izz;
  }
  // The model's state at rest in the shuttle's frame with the elastic coordinates e.
  VectorXd state(const VectorXd& e) const {
    VectorXd y = VectorXd::Zero(m.nl->state_size());
    y.segment(6, ne) = e;
    return y;
  }
  static scoleid::io::Scenario scenario() {
    auto sc = builtin("paper-scole-1");
    sc.scole.actuator_mass = 1e-9;
    sc.scole.reflector.Iyy = 3500;
    sc.scole.reflector.Izz = 6500;
    sc.scole.reflector.Ixy = 300;
    sc.scole.reflector.Iyz = -200;
    return sc;
  }
  static VectorXd coefficients(const Model& m) {
    VectorXd c = scole_coefficients(m.fe.spec);
    for (int k : {ScoleFE::kRhoA, ScoleFE::kRhoIPsi, ScoleFE::kMReflector}) c[k] *= 1e-12;
    for (int k : {ScoleFE::kEIRoll, ScoleFE::kEIPitch, ScoleFE::kGJ, ScoleFE::kKActuator}) c[k] = 0.0;
    return c;
  }
};

TEST(ScoleNonlinear, TheReflectorsRotationalEnergyIsTheTurningBodysExactly) {
  // The reflector's rotational kinetic energy in the model (a rigid body on the mast's end whose
  // points all move with the end section exactly) against ½ ωᵀ R J Rᵀ ω with ω = axial(Ṙ Rᵀ) of the
  // exact section rotation R at the mast's end, computed here independently, for e and ė scaled by
  // ε up to large rotations: equal but for rounding and the differences' error. (A rotor carried to
  // second order, as the mast's sections are, differs at fourth order in ε.) Every other mass is made negligible,
  // the stiffnesses zero. A general inertia, not the flat SCOLE reflector's.
  const ReflectorOnly r;
  const Model& m = r.m;
  const int ne = r.ne;
  const auto deflection = random_deflection(ne, 9);
  const VectorXd &e0 = deflection.first, &v0 = deflection.second;
  const double L = m.sc.scole.length;
  for (double eps : {0.01, 0.05, 0.2}) {
    const VectorXd e = eps * e0, ed = eps * v0;
    VectorXd y = r.state(e);
    y.tail(ne) = ed;
    const double d = 1e-4;
    auto R_at = [&](double t) { return section_rotation(m.fe, ne, VectorXd(e + t * ed), L); };
    const Matrix3d R = R_at(0.0);
    const Matrix3d Rdot = (R_at(-2 * d) - 8.0 * R_at(-d) + 8.0 * R_at(d) - R_at(2 * d)) / (12 * d);
    const Matrix3d W = Rdot * R.transpose();
    const Vector3d w(0.5 * (W(2, 1) - W(1, 2)), 0.5 * (W(0, 2) - W(2, 0)), 0.5 * (W(1, 0) - W(0, 1)));
    const double exact = 0.5 * w.dot(R * r.J * R.transpose() * w), model = r.dyn.energy(y.data());
    std::printf("  eps %.2f  |theta_L| %.3f  exact %.6e  relative difference %.2e\n", eps,
                (m.fe.mast_rotation(L).leftCols(ne) * e).norm(), exact, std::abs(model - exact) / exact);
    EXPECT_LT(std::abs(model - exact), 1e-9 * exact);
  }
}

TEST(ScoleNonlinear, TheReflectorsInertiaTurnsExactlyInASpinningFrame) {
  // The frame spins at a fixed rate Ω₀ while the mast holds a static deflection εe₀: the
  // reflector's kinetic energy changes by ½ Ω₀ᵀ (R J Rᵀ − J) Ω₀ with R the exact section rotation
  // at the mast's end — the centrifugal stiffness of a body turned in a spinning frame (a roll slew
  // that tilts the reflector about pitch trades I_xx for I_zz). The model's change equals it but
  // for rounding at every ε (a rotor turned to second order differs at third order). Every
  // other mass is made negligible (the shuttle's energy, constant, is subtracted at e = 0), the
  // stiffnesses zero.
  const ReflectorOnly r;
  const int ne = r.ne;
  const Matrix3d& J = r.J;
  const VectorXd e0 = random_deflection(ne, 11).first;
  const Vector3d W0(0.07, -0.03, 0.05);
  auto model_energy = [&](const VectorXd& e) {
    VectorXd y = r.state(e);
    y.segment<3>(6 + ne + 3) = W0;
    return r.dyn.energy(y.data());
  };
  const double E0 = model_energy(VectorXd::Zero(ne));
  for (double eps : {0.01, 0.05, 0.2}) {
    const Matrix3d R = section_rotation(r.m.fe, ne, VectorXd(eps * e0), r.m.sc.scole.length);
    const double exact = 0.5 * W0.dot((R * J * R.transpose() - J) * W0), model = model_energy(eps * e0) - E0;
    std::printf("  eps %.2f  exact change %+.6e  relative difference %.2e\n", eps, exact, std::abs(model - exact) / std::abs(exact));
    EXPECT_LT(std::abs(model - exact), 1e-8 * std::abs(exact));
  }
}

TEST(ScoleNonlinear, TheMastsKineticEnergyIsTheShiftedPointsToFourthOrder) {
  // An inextensible mast's points come back towards the root by w(s) = ½ ∫₀ˢ |u'|² ds as it bends.
  // Their kinetic energy, ½ Σ m |V + Ω × (p + N e + t w) + N ė + t ẇ|² over the model's mass
  // points (four Gauss points per element), is computed here with w and ẇ integrated
  // independently (three Gauss points on each element and on the part of a point's own element,
  // ẇ by a central difference in time), for e and ė scaled by ε and a general rigid motion. The
  // model keeps the shift's cross term with the point's velocity and its axial inertia ½ m ẇ²
  // (docs/theory.md §3.8) and leaves out ½ m w² |Ω × t|²: its energy differs at fourth order in ε
  // (without the shift the difference is of second order, the shift's work against the rigid
  // motion), and not at all when the shuttle spins about the mast (Ω × t = 0; without ½ m ẇ² the
  // difference would be of fourth order there too). Every other body's e-dependent mass is made
  // negligible; the shuttle's rigid energy is the same at every ε.
  auto sc = builtin("paper-scole-1");
  sc.scole.actuator_mass = 1e-13;
  sc.scole.reflector.Ixx = sc.scole.reflector.Iyy = sc.scole.reflector.Izz = 1e-13;
  sc.scole.reflector.Ixy = sc.scole.reflector.Ixz = sc.scole.reflector.Iyz = 0.0;
  const int elements = 4;
  const Model m = make_model(sc, elements);
  VectorXd c = scole_coefficients(m.fe.spec);
  for (int k : {ScoleFE::kRhoIPsi, ScoleFE::kMReflector}) c[k] *= 1e-16;
  for (int k : {ScoleFE::kEIRoll, ScoleFE::kEIPitch, ScoleFE::kGJ, ScoleFE::kKActuator}) c[k] = 0.0;
  const auto dyn = m.nl->at(c);
  const int ne = m.nl->elastic();
  const double L = sc.scole.length, h = L / elements, rhoA = c[ScoleFE::kRhoA];
  const Vector3d root(m.fe.spec.mast_root[0], m.fe.spec.mast_root[1], m.fe.spec.mast_root[2]), t = Vector3d::UnitZ();
  auto rows_e = [&](const Eigen::MatrixXd& rows) { return Eigen::MatrixXd(rows.leftCols(ne)); };
  // w(s) for a deflection e: the squared slopes (the tilt rows θ_x, θ_y) by three Gauss points on
  // every whole element below s and on [element start, s].
  const double g3 = 0.5 * std::sqrt(0.6), x3[3] = {0.5 - g3, 0.5, 0.5 + g3}, w3[3] = {5.0 / 18, 8.0 / 18, 5.0 / 18};
  auto shortening = [&](const VectorXd& e, double s) {
    auto piece = [&](double a, double b) {
      double v = 0.0;
      for (int q = 0; q < 3; ++q) {
        const Eigen::VectorXd th = rows_e(m.fe.mast_rotation(a + x3[q] * (b - a))).topRows(2) * e;
        v += w3[q] * (b - a) * 0.5 * th.squaredNorm();
      }
      return v;
    };
    const int el = std::min(static_cast<int>(s / h), elements - 1);
    double v = piece(el * h, s);
    for (int k = 0; k < el; ++k) v += piece(k * h, (k + 1) * h);
    return v;
  };
  const double a4 = std::sqrt(3.0 / 7.0 - 2.0 / 7.0 * std::sqrt(1.2)), b4 = std::sqrt(3.0 / 7.0 + 2.0 / 7.0 * std::sqrt(1.2));
  const double wa = (18.0 + std::sqrt(30.0)) / 36.0, wb = (18.0 - std::sqrt(30.0)) / 36.0;
  const double x4[4] = {0.5 * (1 - b4), 0.5 * (1 - a4), 0.5 * (1 + a4), 0.5 * (1 + b4)};
  const double w4[4] = {0.5 * wb, 0.5 * wa, 0.5 * wa, 0.5 * wb};
  const Vector3d V(0.3, -0.2, 0.5);
  Vector3d W(0.07, -0.03, 0.05);
  auto exact = [&](const VectorXd& e, const VectorXd& ed) {
    double T = 0.0;
    for (int el = 0; el < elements; ++el)
      for (int q = 0; q < 4; ++q) {
        const double s = (el + x4[q]) * h, mass = rhoA * w4[q] * h, dt = 1e-3;
        const Eigen::MatrixXd N = rows_e(m.fe.mast_displacement(s));
        const double w = shortening(e, s);
        const double wd = (shortening(VectorXd(e + dt * ed), s) - shortening(VectorXd(e - dt * ed), s)) / (2 * dt);
        const Vector3d p = root - s * Vector3d::UnitZ();
        const Vector3d v = V + W.cross(p + N * e + t * w) + N * ed + t * wd;
        const Vector3d v0 = V + W.cross(p);
        T += 0.5 * mass * (v.squaredNorm() - v0.squaredNorm());
      }
    return T;
  };
  auto model = [&](const VectorXd& e, const VectorXd& ed) {
    VectorXd y = VectorXd::Zero(m.nl->state_size());
    y.segment(6, ne) = e;
    y.segment<3>(6 + ne) = V;
    y.segment<3>(9 + ne) = W;
    y.tail(ne) = ed;
    return dyn.energy(y.data());
  };
  const auto deflection = random_deflection(ne, 5);
  const VectorXd &e0 = deflection.first, &v0 = deflection.second;
  const double base = model(VectorXd::Zero(ne), VectorXd::Zero(ne));
  expect_order(3.6, [&](double eps) {
    const VectorXd e = eps * e0, ed = eps * v0;
    const double Ex = exact(e, ed);
    return std::make_pair(Ex, std::abs(model(e, ed) - base - Ex));
  });
  // Spinning about the mast: what is left is rounding on the rigid energy (about 10⁴) and the other
  // bodies' negligible (not zero) masses, far below the fourth-order difference of the general
  // motion at the same ε.
  const Vector3d W_general = W, W_axial(0.0, 0.0, W.norm());
  auto difference = [&](const Vector3d& w, double eps) {
    W = w;
    const VectorXd e = eps * e0, ed = eps * v0;
    return std::abs(model(e, ed) - model(VectorXd::Zero(ne), VectorXd::Zero(ne)) - exact(e, ed));
  };
  for (double eps : {0.08, 0.04, 0.02}) {
    const double general = difference(W_general, eps), axial = difference(W_axial, eps);
    std::printf("  eps %.2f  difference: general rigid motion %.3e, spinning about the mast %.3e\n", eps, general, axial);
    EXPECT_LT(axial, 1e-3 * general) << "eps " << eps;
  }
}

TEST(TurnedArm, IsTheEndSectionsRotationOfTheArmWithItsDerivatives) {
  // ρ(θ) = R(θ) r against the rotation built independently (the tilt by the angle asin|θ⊥| about
  // θ⊥, then the twist ψ about ẑ), and its derivatives against central differences of the next
  // lower one, at a large rotation; at θ = 0 its slope is θ × r.
  const Vector3d arm(3.0, -2.0, 0.5);
  const double h = 1e-5;
  for (const Vector3d& th : {Vector3d(0.3, -0.2, 0.4), Vector3d(-0.05, 0.6, -1.1), Vector3d(0.0, 0.0, 0.0)}) {
    const TurnedArm t = turned_arm(th, arm);
    const Vector3d tp(th[0], th[1], 0.0);
    Matrix3d T = Matrix3d::Identity();
    if (tp.norm() > 0) T = Eigen::AngleAxisd(std::asin(tp.norm()), tp.normalized()).toRotationMatrix();
    const Vector3d exact = T * Eigen::AngleAxisd(th[2], Vector3d::UnitZ()).toRotationMatrix() * arm;
    EXPECT_LT((t.value - exact).norm(), 1e-14 * arm.norm());
    double e1 = 0, e2 = 0, e3 = 0;
    for (int k = 0; k < 3; ++k) {
      const Vector3d d = h * Vector3d::Unit(k);
      const TurnedArm p = turned_arm(th + d, arm), m = turned_arm(th - d, arm);
      e1 = std::max(e1, ((p.value - m.value) / (2 * h) - t.d1.col(k)).norm());
      for (std::size_t i = 0; i < 3; ++i) {
        e2 = std::max(e2, ((p.d1.row(static_cast<Eigen::Index>(i)) - m.d1.row(static_cast<Eigen::Index>(i))).transpose() / (2 * h) -
                           t.d2[i].col(k)).norm());
        for (std::size_t l = 0; l < 3; ++l)
          e3 = std::max(e3, ((p.d2[i].row(static_cast<Eigen::Index>(l)) - m.d2[i].row(static_cast<Eigen::Index>(l))).transpose() /
                                 (2 * h) -
                             t.d3[i][l].col(k))
                                .norm());
      }
    }
    std::printf("  theta (%+.2f %+.2f %+.2f): value %.1e, slopes %.1e, 2nd %.1e, 3rd %.1e off\n", th[0], th[1], th[2],
                (t.value - exact).norm(), e1, e2, e3);
    EXPECT_LT(e1, 1e-8);
    EXPECT_LT(e2, 1e-8);
    EXPECT_LT(e3, 1e-8);
    // The contractions are the tensors'.
    const Vector3d a(0.2, -0.7, 0.4), b(-0.3, 0.1, 0.9), w(0.5, 0.6, -0.2);
    EXPECT_NEAR(t.second_t(b, w).dot(a), w.dot(t.second(a, b)), 1e-14 * arm.norm());
    const Vector3d g = t.third_t(a, w);
    for (int k = 0; k < 3; ++k) {
      const Vector3d d = h * Vector3d::Unit(k);
      const double fd = (w.dot(turned_arm(th + d, arm).second(a, a)) - w.dot(turned_arm(th - d, arm).second(a, a))) / (2 * h);
      EXPECT_NEAR(g[k], fd, 1e-8);
    }
  }
  EXPECT_LT((turned_arm(Vector3d::Zero(), arm).d1 + skew(arm)).norm(), 1e-15);
  EXPECT_THROW(turned_arm(Vector3d(0.8, 0.6, 0.0), arm), std::domain_error);
}

TEST(ScoleNonlinear, TheReflectorsCMIsTheArmTurnedExactlyByTheEndSection) {
  // The reflector's CM r(e) = p + u(L) + t ½ ∫ |u'|² ds + R(θ_L) a − a, R the end section's exact
  // rotation (section_rotation) and a the arm, computed here independently: against it, the
  // model's CM velocity (from the linear momentum, every other moving mass negligible) and its
  // acceleration at rest (from an accelerometer there: N(e) ë + r''[ė, ė]) along e + t ė + ½ t² ë,
  // by differences of r in t. Equal to the differences' error at every amplitude ε, up to large
  // ones (|θ_L| 0.36); an arm turned to second order would leave ⅙ [θ]³ a, of third order.
  auto sc = builtin("paper-scole-1");
  sc.scole.actuator_mass = 1e-9;
  sc.scole.reflector.Ixx = sc.scole.reflector.Iyy = sc.scole.reflector.Izz = 1e-9;
  sc.scole.reflector.Ixy = sc.scole.reflector.Ixz = sc.scole.reflector.Iyz = 0.0;
  for (int k = 0; k < 3; ++k) {
    scoleid::io::SensorSpec a;
    a.name = "acc" + std::to_string(k);
    a.at = scoleid::io::Site::Reflector;
    a.kind = scoleid::io::SensorKind::Acceleration;
    a.direction = {k == 0 ? 1.0 : 0.0, k == 1 ? 1.0 : 0.0, k == 2 ? 1.0 : 0.0};
    sc.sensors.push_back(a);
  }
  const int elements = 4;
  const Model m = make_model(sc, elements);
  VectorXd c = scole_coefficients(m.fe.spec);
  for (int k : {ScoleFE::kRhoA, ScoleFE::kRhoIPsi}) c[k] *= 1e-12;
  for (int k : {ScoleFE::kEIRoll, ScoleFE::kEIPitch, ScoleFE::kGJ, ScoleFE::kKActuator}) c[k] = 0.0;
  const auto dyn = m.nl->at(c);
  const int ne = m.nl->elastic(), ns = m.nl->sensors();
  const double L = sc.scole.length, h = L / elements, mr = c[ScoleFE::kMReflector];
  const Vector3d arm(sc.scole.reflector_rx, sc.scole.reflector_ry, 0.0);
  const Vector3d p = Vector3d(sc.scole.mast_root[0], sc.scole.mast_root[1], sc.scole.mast_root[2]) - L * Vector3d::UnitZ();
  const double g3 = 0.5 * std::sqrt(0.6), x3[3] = {0.5 - g3, 0.5, 0.5 + g3}, w3[3] = {5.0 / 18, 8.0 / 18, 5.0 / 18};
  auto cm = [&](const VectorXd& e) {
    double w = 0.0;  // ½ ∫ |u'|² (the tilt rows' squares: degree 4 on an element, three Gauss points)
    for (int el = 0; el < elements; ++el)
      for (int q = 0; q < 3; ++q)
        w += w3[q] * h * 0.5 * (m.fe.mast_rotation((el + x3[q]) * h).leftCols(ne).topRows(2) * e).squaredNorm();
    return Vector3d(p + m.fe.mast_displacement(L).leftCols(ne) * e + w * Vector3d::UnitZ() +
                    section_rotation(m.fe, ne, e, L) * arm);
  };
  const Vector3d W(0.07, -0.03, 0.05);
  const auto deflection = random_deflection(ne, 21);
  const VectorXd &e0 = deflection.first, &v0 = deflection.second, a0 = random_deflection(ne, 22).first;
  for (double eps : {0.01, 0.1, 1.0}) {
    const VectorXd e = eps * e0, ed = eps * v0, edd = eps * a0;
    const double d = 1e-2;
    auto at = [&](double t) { return Vector3d(cm(VectorXd(e + t * ed + 0.5 * t * t * edd)) - p); };
    // Fourth-order differences: truncation ~d⁴, rounding ~1e-16 |a| / d².
    const Vector3d v = (at(-2 * d) - 8.0 * at(-d) + 8.0 * at(d) - at(2 * d)) / (12 * d);
    const Vector3d acc = (-at(-2 * d) + 16.0 * at(-d) - 30.0 * at(0.0) + 16.0 * at(d) - at(2 * d)) / (12 * d * d);
    VectorXd y = VectorXd::Zero(m.nl->state_size()), y0 = y;
    y.segment(6, ne) = e;
    y.segment<3>(9 + ne) = W;
    y.tail(ne) = ed;
    y0.segment<3>(9 + ne) = W;
    const Vector3d vel = (dyn.momentum(y.data()) - dyn.momentum(y0.data())) / mr;  // the others: ~1e-12
    const Vector3d vel_exact = W.cross(cm(e) - cm(VectorXd::Zero(ne))) + v;
    VectorXd rest = y;
    rest.segment<3>(9 + ne).setZero();
    VectorXd udot = VectorXd::Zero(m.nl->speeds());
    udot.tail(ne) = edd;
    const VectorXd z = dyn.outputs(rest.data(), udot);
    const Vector3d acc_model(z[ns - 3], z[ns - 2], z[ns - 1]);
    const double ev = (vel - vel_exact).norm() / vel_exact.norm(), ea = (acc_model - acc).norm() / acc.norm();
    std::printf("  eps %.2f  |theta_L| %.3f  velocity %.2e  acceleration %.2e off (relative)\n", eps,
                (m.fe.mast_rotation(L).leftCols(ne) * e).norm(), ev, ea);
    EXPECT_LT(ev, 1e-9);
    EXPECT_LT(ea, 1e-9);
  }
}

TEST(ScoleNonlinear, UndampedFreeMotionConservesEnergyAndMomenta) {
  // Spinning about all three axes (turning through about a radian) while the mast vibrates; no
  // damping, no inputs, free proof masses.
  auto sc = builtin("paper-scole-1");
  sc.scole.EI_pitch = 0.85 * sc.scole.EI_roll;  // every term of the cubic strain energy
  sc.scole.GJ = 0.75 * sc.scole.EI_roll;
  sc.scole.zeta = 0.0;
  sc.scole.actuator_damping = 0.0;
  sc.inputs.clear();
  sc.sensors = {sc.sensors.front()};
  sc.sensors.front().at = scoleid::io::Site::Shuttle;
  sc.sensors.front().kind = scoleid::io::SensorKind::Rotation;
  sc.sensors.front().direction = {1, 0, 0};
  const Model m = make_model(sc, 6);
  const auto dyn = m.nl->at(scole_coefficients(m.fe.spec));
  const int ne = m.nl->elastic();
  VectorXd y0 = VectorXd::Zero(m.nl->state_size());
  // At rest elastically: the spin itself (Euler, centrifugal and Coriolis terms) sets the mast
  // vibrating, without exciting the mesh's highest modes.
  y0.segment<3>(6 + ne) = Vector3d(0.3, -0.2, 0.1);       // V [ft/s]
  y0.segment<3>(9 + ne) = Vector3d(0.05, 0.03, -0.04);    // Ω [rad/s]
  NonlinearForwardOptions opt;
  opt.max_step = 2e-3;
  const auto r = simulate_nonlinear(dyn, {}, sample_times(10.0, 0.5), opt, y0);
  double flex = 0;
  for (const auto& y : r.states) flex = std::max(flex, y.segment(6, ne).cwiseAbs().maxCoeff());
  const double E0 = dyn.energy(y0.data());
  const Vector3d P0 = dyn.momentum(y0.data()), H0 = dyn.angular_momentum(y0.data());
  double dE = 0, dP = 0, dH = 0, turn = 0;
  for (const auto& y : r.states) {
    dE = std::max(dE, std::abs(dyn.energy(y.data()) - E0) / E0);
    dP = std::max(dP, (dyn.momentum(y.data()) - P0).norm() / P0.norm());
    dH = std::max(dH, (dyn.angular_momentum(y.data()) - H0).norm() / H0.norm());
    turn = std::max(turn, y.segment<3>(3).norm());
  }
  std::printf("  largest elastic DOF %.2e; turned %.3f rad; drift: energy %.2e, momentum %.2e, angular momentum %.2e (%ld steps)\n", flex, turn, dE,
              dP, dH, r.summary.steps);
  EXPECT_GT(turn, 0.5);
  EXPECT_GT(flex, 1e-4);
  EXPECT_LT(dE, 1e-7);
  EXPECT_LT(dP, 1e-7);
  EXPECT_LT(dH, 1e-7);
}

TEST(ScoleNonlinear, SmallPulsesGiveTheLinearResponseUpToSecondOrder) {
  // Paper Case I's pulses, scaled: the difference to the linear model is of second order in the
  // amplitude (relative to the signal it falls in proportion to the amplitude, i.e. to the angle
  // the shuttle turns through), and below 1e-6 of the signal once that angle is below 1e-5 rad.
  const auto sc = builtin("paper-scole-1");
  const int elements = 6;
  const Model m = make_model(sc, elements);
  const auto dyn = m.nl->at(scole_coefficients(m.fe.spec));
  NonlinearForwardOptions opt;
  opt.max_step = 2e-3;
  const auto times = sample_times(sc.simulation.duration, sc.simulation.sample_interval);
  const double scales[3] = {1.0, 0.1, 5e-4};
  double worst[3] = {0, 0, 0}, turn[3] = {0, 0, 0};
  for (int k = 0; k < 3; ++k) {
    const auto r = simulate_nonlinear(dyn, signals_of(sc, scales[k]), times, opt);
    for (const auto& y : r.states) turn[k] = std::max(turn[k], y.segment<3>(3).norm());
    const MatrixXd lin = linear_response(sc, elements, scales[k], opt.max_step);
    ASSERT_EQ(lin.rows(), r.outputs.rows());
    for (int j = 0; j < lin.cols(); ++j) {
      const double d = relative_rms(r.outputs.col(j), lin.col(j));
      std::printf("  scale %.0e %-12s relative RMS difference %.3e\n", scales[k],
                  m.nl->sensor_names()[static_cast<std::size_t>(j)].c_str(), d);
      worst[k] = std::max(worst[k], d);
    }
    std::printf("  scale %.0e: shuttle turns %.3e rad; %ld steps, %ld f evaluations, %ld Jacobians, %.2f s\n",
                scales[k], turn[k], r.summary.steps, r.summary.rhs_evaluations, r.summary.jacobian_evaluations,
                r.summary.seconds);
  }
  EXPECT_NEAR(worst[1] / worst[0], 0.1, 0.01);
  EXPECT_NEAR(worst[2] / worst[0], 5e-4, 1e-4);
  EXPECT_LT(turn[2], 1e-5);
  EXPECT_LT(worst[2], 1e-6);
}

TEST(ScoleNonlinear, SlewReachesTheRigidBodyAngleWhereTheLinearModelDeparts) {
  const auto sc = builtin("scole-slew");
  const int elements = 6;
  const Model m = make_model(sc, elements);
  const auto dyn = m.nl->at(scole_coefficients(m.fe.spec));
  const auto times = sample_times(sc.simulation.duration, 0.05);
  NonlinearForwardOptions opt;
  opt.max_step = 5e-3;
  const auto r = simulate_nonlinear(dyn, signals_of(sc), times, opt);
  // Rest-to-rest rigid slew: A w² / (4 I_roll) about the whole system's roll axis (the
  // scenario's own numbers; the products of inertia tip the axis slightly, the mast rings).
  const auto& sig = sc.inputs.front().signal.terms().front();
  // I_roll of the whole configuration about its CM from the model's rigid mass matrix.
  const MatrixXd M0 = dyn.mass(VectorXd::Zero(m.nl->elastic()));
  const Matrix3d Mvv = M0.topLeftCorner<3, 3>(), Mvw = M0.block<3, 3>(0, 3), Mww = M0.block<3, 3>(3, 3);
  const Matrix3d Icm = Mww - Mvw.transpose() * Mvv.inverse() * Mvw;
  const double expected = sig.amplitude * sig.width * sig.width / (4.0 * Icm(0, 0));
  const int roll = 0;
  const double final_roll = r.outputs(r.outputs.rows() - 1, roll);
  std::printf("  roll at the end %.5f rad, rigid-body %.5f rad (%.2e); %ld steps, %.2f s\n", final_roll, expected,
              final_roll / expected - 1.0, r.summary.steps, r.summary.seconds);
  EXPECT_NEAR(final_roll / expected, 1.0, 0.01);
  // The linear model on the same record, sampled alike: its departure per sensor.
  auto lin_sc = sc;
  lin_sc.simulation.sample_interval = 0.05;
  const MatrixXd lin = linear_response(lin_sc, elements, 1.0, opt.max_step);
  ASSERT_EQ(lin.rows(), r.outputs.rows());
  double worst = 0;
  for (int j = 0; j < lin.cols(); ++j) {
    const double d = relative_rms(lin.col(j), r.outputs.col(j));
    std::printf("  %-10s linear vs nonlinear: relative RMS difference %.3e\n",
                m.nl->sensor_names()[static_cast<std::size_t>(j)].c_str(), d);
    worst = std::max(worst, d);
  }
  EXPECT_GT(worst, 0.05);
}

namespace {
// Every input kind and every sensor kind, on a general configuration (root off the CM, products
// of inertia, actuator springs and dampers, damping, EI_roll ≠ EI_pitch ≠ GJ: every term of the
// cubic strain energy).
const char* const kEveryKind = R"(name: nonlinear-every-kind
structure: scole
scole: {mast_root: [1.5, -2.0, 3.0], zeta: 0.01, actuator_stiffness: 30, actuator_damping: 2, EI_pitch: 3.4e7, GJ: 3.0e7,
        shuttle: {Ixy: 1200, Ixz: -3000}, reflector: {Izz: 9000, Ixy: 150, Iyz: 40}}
inputs:
  - {name: F_sx, at: shuttle, kind: force, direction: x, signal: {type: haversine, amplitude: 500, t0: 0, width: 0.4}}
  - {name: M_sy, at: shuttle, kind: moment, direction: y, signal: {type: haversine, amplitude: 5000, t0: 0.1, width: 0.4}}
  - {name: F_ry, at: reflector, kind: force, direction: y, signal: {type: haversine, amplitude: 10, t0: 0, width: 0.3}}
  - {name: M_rz, at: reflector, kind: moment, direction: z, signal: {type: haversine, amplitude: 200, t0: 0.2, width: 0.3}}
  - {name: F_mx, at: mast, kind: force, location: 65, direction: x, signal: {type: haversine, amplitude: 10, t0: 0.1, width: 0.3}}
  - {name: F_a1, at: actuator1, kind: force, direction: y, signal: {type: bangbang, amplitude: 10, t0: 0, width: 0.4}}
sensors:
  - {name: s_rot, at: shuttle, kind: rotation, direction: [0.6, 0.8, 0]}
  - {name: s_disp, at: shuttle, kind: displacement, direction: [0, 0.6, 0.8]}
  - {name: s_vel, at: shuttle, kind: velocity, direction: x}
  - {name: s_acc, at: shuttle, kind: acceleration, direction: [0.8, 0, 0.6]}
  - {name: d_tip_y, at: mast, kind: displacement, location: 130, direction: y}
  - {name: r_refl_z, at: reflector, kind: rotation, direction: z}
  - {name: los_x, at: reflector, kind: line_of_sight, direction: x}
  - {name: v_tip_y, at: mast, kind: velocity, location: 130, direction: y}
  - {name: a_tip_x, at: mast, kind: acceleration, location: 130, direction: x}
  - {name: a_refl, at: reflector, kind: acceleration, direction: [0, 0.6, 0.8]}
simulation: {duration: 2, sample_interval: 0.01, seed: 1}
identification:
  parameterization: physical
  estimate: [EI_roll, EI_pitch, GJ, rho_A]
  elements: 4
)";

// A state well away from rest: turned, spinning, deformed, vibrating.
VectorXd moving_state(const ScoleNonlinear& nl, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> N(0.0, 1.0);
  const int ne = nl.elastic();
  VectorXd y(nl.state_size());
  for (int i = 0; i < 3; ++i) {
    y[i] = 10.0 * N(rng);
    y[3 + i] = 0.5 * N(rng);
    y[6 + ne + i] = N(rng);
    y[9 + ne + i] = 0.1 * N(rng);
  }
  for (int i = 0; i < ne; ++i) {
    y[6 + i] = 0.05 * N(rng);
    y[12 + ne + i] = 0.05 * N(rng);
  }
  return y;
}
}  // namespace

TEST(ScoleNonlinear, TheAccelerationsSatisfyTheEquationsWithTheWholeMassMatrix) {
  // derivative() solves M(e) u̇ = Q − b iteratively (the banded factor and the Schur complement
  // precondition conjugate gradients for the mast's dense axial inertia, docs/theory.md §3.8);
  // residual() multiplies by the assembled M(e). At moving states with random deflections, and
  // four times them, the two must agree to rounding (solving with the preconditioner alone leaves
  // the axial inertia's share: 0.15–0.6 of |M u̇| at these deflections).
  const Model m = make_model(scoleid::io::parse_scenario(kEveryKind, "every-kind"), 4);
  const ScoleNonlinear& nl = *m.nl;
  const auto dyn = nl.at(scole_coefficients(m.fe.spec));
  const int n = nl.state_size(), ne = nl.elastic();
  std::mt19937_64 rng(5);
  std::normal_distribution<double> N(0.0, 1.0);
  VectorXd fin(nl.inputs());
  for (int i = 0; i < fin.size(); ++i) fin[i] = 100.0 * N(rng);
  for (unsigned seed : {1u, 2u})
    for (double scale : {1.0, 4.0}) {
      VectorXd y = moving_state(nl, seed);
      y.segment(6, ne) *= scale;
      VectorXd yd(n), udot;
      dyn.derivative(y.data(), fin, yd.data(), &udot);
      const VectorXd e = y.segment(6, ne), Mu = dyn.mass(e) * udot;
      const double r = dyn.residual(y.data(), udot, fin).norm() / Mu.norm();
      std::printf("  seed %u, deflection x%.0f: |R| / |M u'| = %.2e\n", seed, scale, r);
      EXPECT_LT(r, 1e-11);
    }
}

TEST(ScoleNonlinear, TheVelocityForcesAreTheMassMatrixsChristoffelTerms) {
  // With the shuttle at rest (V = Ω = 0) and the mast moving (ė), the part of the residual
  // quadratic in ė is Lagrange's  Ṁ u − [0; ½ ∇_e (uᵀ M u)]  for u = (0, 0, ė) (the rigid rows
  // by Boltzmann–Hamel, whose Ω-terms vanish here): every velocity force, the axial inertia's
  // m g ėᵀ Q ė among them, must be what the assembled M(e) implies. ½ (R(ė) + R(−ė)) − R(0) at
  // u̇ = 0 and no load isolates that part (damping is odd in ė); M's derivatives by central
  // differences of mass(e).
  const Model m = make_model(scoleid::io::parse_scenario(kEveryKind, "every-kind"), 4);
  const ScoleNonlinear& nl = *m.nl;
  const auto dyn = nl.at(scole_coefficients(m.fe.spec));
  const int nu = nl.speeds(), ne = nl.elastic();
  const VectorXd f0 = VectorXd::Zero(nl.inputs()), a0 = VectorXd::Zero(nu);
  for (unsigned seed : {1u, 2u})
    for (double scale : {1.0, 4.0}) {
      VectorXd y = moving_state(nl, seed);
      y.segment(6, ne) *= scale;
      y.segment<6>(6 + ne).setZero();
      const VectorXd e = y.segment(6, ne), ed = y.tail(ne);
      auto R = [&](double sgn) {
        VectorXd ys = y;
        ys.tail(ne) = sgn * ed;
        return dyn.residual(ys.data(), a0, f0);
      };
      const VectorXd quad = 0.5 * (R(1.0) + R(-1.0)) - R(0.0);
      VectorXd u = VectorXd::Zero(nu);
      u.tail(ne) = ed;
      const double h = 1e-5;
      VectorXd lag = (dyn.mass(e + h * ed) - dyn.mass(e - h * ed)) / (2 * h) * u;
      for (int k = 0; k < ne; ++k) {
        const VectorXd dk = h * VectorXd::Unit(ne, k);
        lag[6 + k] -= 0.5 * (u.dot(dyn.mass(e + dk) * u) - u.dot(dyn.mass(e - dk) * u)) / (2 * h);
      }
      const double err = (quad - lag).norm() / lag.norm();
      std::printf("  seed %u, deflection x%.0f: |quadratic force - Christoffel terms| / |those| = %.1e\n", seed, scale, err);
      EXPECT_LT(err, 1e-7);
    }
}

TEST(ScoleNonlinear, TransposedProductsMatchCentralDifferences) {
  const Model m = make_model(scoleid::io::parse_scenario(kEveryKind, "every-kind"), 4);
  const ScoleNonlinear& nl = *m.nl;
  const VectorXd c = scole_coefficients(m.fe.spec);
  const auto dyn = nl.at(c);
  const int n = nl.state_size(), nu = nl.speeds(), ne = nl.elastic();
  std::mt19937_64 rng(11);
  std::normal_distribution<double> N(0.0, 1.0);
  VectorXd fin(nl.inputs());
  for (int i = 0; i < fin.size(); ++i) fin[i] = 100.0 * N(rng);
  auto rhs = [&](const VectorXd& y, const ScoleNonlinear::Dynamics& d) {
    VectorXd yd(n);
    d.derivative(y.data(), fin, yd.data());
    return yd;
  };
  for (unsigned seed : {1u, 2u}) {
    const VectorXd y = moving_state(nl, seed);
    const VectorXd yd = rhs(y, dyn);
    VectorXd lambda(n), dir(n), rho(nl.sensors());
    for (int i = 0; i < n; ++i) lambda[i] = N(rng);
    for (int i = 0; i < n; ++i) dir[i] = N(rng) * (std::abs(y[i]) + 1e-2);
    for (int i = 0; i < rho.size(); ++i) rho[i] = N(rng);
    const double eps = 1e-5;
    // (∂f/∂y)ᵀ λ against λᵀ (f(y + εd) − f(y − εd)) / 2ε.
    const double fd = lambda.dot(rhs(y + eps * dir, dyn) - rhs(y - eps * dir, dyn)) / (2 * eps);
    const double an = dyn.derivative_vjp(y.data(), fin, yd, lambda).dot(dir);
    std::printf("  seed %u: state product %.10e vs differences %.10e (%.1e)\n", seed, an, fd, std::abs(an / fd - 1));
    EXPECT_NEAR(an / fd, 1.0, 1e-7);
    // The same along the deflection and along its rate alone (each block's terms on their own; a
    // fourth-order difference: the rate's share of f is small beside f, so rounding limits a
    // narrow step).
    for (const auto& block : {std::make_pair(6, ne), std::make_pair(12 + ne, ne)}) {
      VectorXd d = VectorXd::Zero(n);
      d.segment(block.first, block.second) = dir.segment(block.first, block.second);
      const double anb = dyn.derivative_vjp(y.data(), fin, yd, lambda).dot(d), h = 1e-3;
      const double fdb =
          lambda.dot(rhs(y - 2 * h * d, dyn) - 8.0 * rhs(y - h * d, dyn) + 8.0 * rhs(y + h * d, dyn) - rhs(y + 2 * h * d, dyn)) /
          (12 * h);
      std::printf("    along %s: %.1e\n", block.first == 6 ? "e" : "e-dot", std::abs(anb / fdb - 1));
      EXPECT_NEAR(anb / fdb, 1.0, 1e-7) << (block.first == 6 ? "along e" : "along e-dot");
    }
    // λᵀ ∂f/∂c, coefficient by coefficient. f is affine in the stiffness and damping coefficients
    // (wide central differences: exact but for rounding, where narrow ones would drown the
    // damping's small share of f in it); the mass coefficients enter through M⁻¹ (narrow steps).
    const VectorXd gc = dyn.coefficient_vjp(y.data(), fin, yd, lambda);
    for (int k = 0; k < c.size(); ++k) {
      const bool inertia = k == ScoleFE::kRhoA || k == ScoleFE::kRhoIPsi || k == ScoleFE::kMReflector;
      const double h = (inertia ? 1e-5 : 0.1) * std::abs(c[k]);
      VectorXd cp = c, cm = c;
      cp[k] += h;
      cm[k] -= h;
      const double fdc = lambda.dot(rhs(y, nl.at(cp)) - rhs(y, nl.at(cm))) / (2 * h);
      EXPECT_NEAR(gc[k], fdc, (inertia ? 1e-7 : 1e-8) * std::abs(fdc) + 1e-12 * lambda.norm()) << "coefficient " << k;
    }
    // Outputs: ∂/∂y at fixed u̇ and ∂/∂u̇.
    const VectorXd a = yd.tail(nu);
    VectorXd dy, da;
    dyn.outputs_vjp(y.data(), a, rho, dy, da);
    const VectorXd yp = y + eps * dir, ym = y - eps * dir;
    const double fdy = rho.dot(dyn.outputs(yp.data(), a) - dyn.outputs(ym.data(), a)) / (2 * eps);
    EXPECT_NEAR(dy.dot(dir) / fdy, 1.0, 1e-7) << "ρᵀz " << rho.dot(dyn.outputs(y.data(), a)) << ", accelerations " << a.norm();
    VectorXd adir(nu);
    for (int i = 0; i < nu; ++i) adir[i] = N(rng);
    // Linear in u̇: any step is exact.
    const double fda = rho.dot(dyn.outputs(y.data(), VectorXd(a + adir)) - dyn.outputs(y.data(), VectorXd(a - adir))) / 2.0;
    EXPECT_NEAR(da.dot(adir) / fda, 1.0, 1e-9);
  }
}

namespace {
// The every-kind configuration on a short record, its measurements from the nonlinear model at
// perturbed coefficients, and the objective at the nominal ones.
struct GradientCase {
  scoleid::io::Scenario sc;
  std::unique_ptr<Problem> p;
  Model m;
  Measurements data;
  std::unique_ptr<NonlinearObjective> obj;
  VectorXd c;
};

std::unique_ptr<GradientCase> gradient_case(double duration) {
  auto g = std::make_unique<GradientCase>();
  g->sc = scoleid::io::parse_scenario(kEveryKind, "every-kind");
  g->sc.simulation.duration = duration;
  g->sc.simulation.sample_interval = 0.02;
  g->p = make_problem(g->sc, std::nullopt);
  g->m = make_model(g->sc, g->sc.identification.elements);
  g->c = scole_coefficients(g->m.fe.spec);
  VectorXd ct = g->c;
  for (int k = 0; k < ct.size(); ++k) ct[k] *= 1.0 + 0.03 * std::sin(1.0 + k);
  const auto times = sample_times(duration, 0.02);
  NonlinearForwardOptions opt;
  opt.max_step = 5e-3;
  g->data.names = g->m.nl->sensor_names();
  g->data.t = times;
  g->data.z = simulate_nonlinear(g->m.nl->at(ct), g->p->signals, times, opt).outputs;
  g->obj = std::make_unique<NonlinearObjective>(*g->m.nl, *g->p->params, g->p->signals, g->data, opt);
  return g;
}
}  // namespace

TEST(ScoleNonlinearCostate, GradientMatchesCentralDifferencesForEveryCoefficient) {
  auto g = gradient_case(0.6);
  VectorXd gc;
  const double J = g->obj->cost_and_coefficient_gradient(g->c, gc);
  const auto& cs = g->obj->last_costate();
  std::printf("  J = %.6e; forward %ld steps, %ld f; costate %ld products, %ld defect iterations, %ld Jacobians\n", J,
              g->obj->last_forward().steps, g->obj->last_forward().rhs_evaluations, cs.products, cs.defect_iterations,
              cs.jacobians);
  for (int k = 0; k < g->c.size(); ++k) {
    // Central differences with Richardson extrapolation (steps 1e-4 and 5e-5 relative).
    auto fd = [&](double rel) {
      VectorXd cp = g->c, cm = g->c;
      const double h = rel * std::abs(g->c[k]);
      cp[k] += h;
      cm[k] -= h;
      VectorXd unused;
      const double Jp = g->obj->cost_and_coefficient_gradient(cp, unused);
      const double Jm = g->obj->cost_and_coefficient_gradient(cm, unused);
      return (Jp - Jm) / (2 * h);
    };
    const double d1 = fd(1e-4), d2 = fd(5e-5);
    const double rich = (4 * d2 - d1) / 3;
    std::printf("  %-12s costate % .10e  differences % .10e  (%.1e)\n",
                g->m.fe.model.coefficient_names[static_cast<std::size_t>(k)].c_str(), gc[k], rich,
                std::abs(gc[k] - rich) / std::abs(rich));
    EXPECT_NEAR(gc[k], rich, 1e-6 * std::abs(rich) + 1e-10 * gc.norm()) << "coefficient " << k;
  }
}

TEST(ScoleNonlinearIdentification, OptionsTheNonlinearModelDoesNotOfferAreRefused) {
  auto sc = builtin("scole-slew-case1");
  sc.identification.method = scoleid::io::Method::GaussNewtonKrylov;
  sc.simulation.duration = 1.0;
  const std::string e = test_support::run_error(sc);
  EXPECT_NE(e.find("identification.method"), std::string::npos) << e;
  auto beam = builtin("paper-beam-1");
  beam.identification.model = scoleid::io::Model::Nonlinear;
  // The door refuses it, naming the field; below the door the model takes the scenario as valid
  // and a caller that went around it is a defect.
  try {
    scoleid::identify::check_scenario(beam);
    ADD_FAILURE() << "a nonlinear beam passed the door";
  } catch (const scoleid::io::InputError& err) {
    EXPECT_NE(std::string(err.what()).find("identification.model"), std::string::npos) << err.what();
  }
  EXPECT_THROW(scole_nonlinear(beam, 4), std::logic_error);
}

TEST(ScoleNonlinearCostate, TaylorRemainderFallsAtSecondOrder) {
  // R(ε) = |J(c ∘ (1 + ε d)) − J(c) − ε ∇J·(c ∘ d)| for a random direction d over every coefficient.
  auto g = gradient_case(0.6);
  VectorXd gc;
  const double J0 = g->obj->cost_and_coefficient_gradient(g->c, gc);
  std::mt19937_64 rng(3);
  std::normal_distribution<double> N(0.0, 1.0);
  VectorXd d(g->c.size());
  for (int k = 0; k < d.size(); ++k) d[k] = N(rng);
  d /= d.norm();
  const VectorXd dc = g->c.cwiseProduct(d);
  const double slope = gc.dot(dc);
  std::vector<double> R;
  for (int k = 0; k < 5; ++k) {
    const double eps = 0.02 / std::pow(2.0, k);
    VectorXd unused;
    R.push_back(std::abs(g->obj->cost_and_coefficient_gradient(g->c + eps * dc, unused) - J0 - eps * slope));
    std::printf("  eps %.4e remainder %.6e ratio %.3f\n", eps, R.back(), k ? R[static_cast<std::size_t>(k) - 1] / R.back() : 0.0);
  }
  for (std::size_t k = 1; k < R.size(); ++k) EXPECT_NEAR(R[k - 1] / R[k], 4.0, 0.3);
}


TEST(ScoleNonlinearCostate, TheDiscreteCostateConvergesToTheCvodesAdjointOfTheContinuousModel) {
  // The same sampled cost on the continuous-time ODE (CVODES BDF at rtol 1e-10, forward and
  // adjoint with the sample jumps): the discrete costate's gradient is that of the ESDIRK
  // solution, so the two differ by the stepping's error and approach each other as h falls. Smooth
  // inputs and no accelerometer, so that the mesh's stiff modes, which the L-stable steps damp and
  // BDF resolves, stay out of the outputs.
  auto sc = scoleid::io::parse_scenario(R"(name: nonlinear-smooth
structure: scole
scole: {mast_root: [1.5, -2.0, 3.0], zeta: 0.01, actuator_stiffness: 30, actuator_damping: 2,
        shuttle: {Ixy: 1200, Ixz: -3000}, reflector: {Izz: 9000, Ixy: 150, Iyz: 40}}
inputs:
  - {name: M_sx, at: shuttle, kind: moment, direction: x, signal: {type: haversine, amplitude: 20000, t0: 0, width: 1.0}}
  - {name: F_ry, at: reflector, kind: force, direction: y, signal: {type: haversine, amplitude: 10, t0: 0, width: 0.8}}
  - {name: F_a1, at: actuator1, kind: force, direction: x, signal: {type: haversine, amplitude: 5, t0: 0.2, width: 0.8}}
sensors:
  - {name: s_rot, at: shuttle, kind: rotation, direction: x}
  - {name: d_tip_y, at: mast, kind: displacement, location: 130, direction: y}
  - {name: r_refl_z, at: reflector, kind: rotation, direction: z}
  - {name: los_x, at: reflector, kind: line_of_sight, direction: x}
  - {name: v_tip_x, at: mast, kind: velocity, location: 130, direction: x}
simulation: {duration: 1.2, sample_interval: 0.02, seed: 1}
identification:
  parameterization: physical
  estimate: [EI, rho_A]
  elements: 4
)", "smooth");
  auto p = make_problem(sc, std::nullopt);
  const Model m = make_model(sc, 4);
  const VectorXd c = scole_coefficients(m.fe.spec);
  VectorXd ct = c;
  for (int k = 0; k < ct.size(); ++k) ct[k] *= 1.0 + 0.03 * std::sin(1.0 + k);
  Measurements data;
  data.names = m.nl->sensor_names();
  data.t = sample_times(1.2, 0.02);
  NonlinearForwardOptions fine;
  fine.max_step = 2.5e-4;
  data.z = simulate_nonlinear(m.nl->at(ct), p->signals, data.t, fine).outputs;
  NonlinearObjective weights_of(*m.nl, *p->params, p->signals, data);
  const auto ref = cvodes_nonlinear_gradient(*m.nl, c, p->signals, data, weights_of.weights(), 1e-10);
  double previous = 0.0;
  for (double h : {4e-3, 1e-3}) {
    NonlinearForwardOptions opt;
    opt.max_step = h;
    NonlinearObjective obj(*m.nl, *p->params, p->signals, data, opt);
    VectorXd gc;
    const double J = obj.cost_and_coefficient_gradient(c, gc);
    const double diff = (gc - ref.gradient).cwiseAbs().maxCoeff() / ref.gradient.cwiseAbs().maxCoeff();
    std::printf("  h %.0e: J %.10e vs %.10e (%.1e); gradient max difference %.2e of the largest entry\n", h, J, ref.cost,
                std::abs(J / ref.cost - 1), diff);
    for (int k = 0; k < gc.size(); ++k)
      std::printf("    %-12s % .8e  % .8e\n", m.fe.model.coefficient_names[static_cast<std::size_t>(k)].c_str(), gc[k],
                  ref.gradient[k]);
    if (previous > 0) {
      EXPECT_LT(diff, previous / 8.0);  // third order: 64 per factor 4 in h
    }
    previous = diff;
  }
  EXPECT_LT(previous, 1e-4);
}
