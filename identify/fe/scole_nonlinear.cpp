#include "scoleid/identify/fe/scole_nonlinear.h"

#include <cmath>
#include <limits>
#include <stdexcept>

#include "scoleid/identify/fe/rotation_vector.h"

namespace scoleid::identify {

using Eigen::Matrix3d;
using Eigen::Vector3d;

namespace {

Vector3d vec3(const std::vector<double>& v) { return {v[0], v[1], v[2]}; }

Matrix3d inertia_matrix(const io::RigidBodySpec& b) {
  // Products as the off-diagonal entries, as the linear model and Simbody's Inertia take them.
  Matrix3d I;
  I << b.Ixx, b.Ixy, b.Ixz, b.Ixy, b.Iyy, b.Iyz, b.Ixz, b.Iyz, b.Izz;
  return I;
}

// State views: y = [X, φ, e, V, Ω, ė].
struct StateView {
  StateView(const double* y, int ne)
      : X(y), phi(y + 3), e(y + 6, ne), V(y + 6 + ne), Omega(y + 9 + ne), edot(y + 12 + ne, ne),
        u(y + 6 + ne, 6 + ne) {}
  Eigen::Map<const Vector3d> X, phi;
  Eigen::Map<const VectorXd> e;
  Eigen::Map<const Vector3d> V, Omega;
  Eigen::Map<const VectorXd> edot, u;
};

}  // namespace

ScoleNonlinear::Rows3 ScoleNonlinear::Rows3::of(const MatrixXd& dense) {
  Rows3 r;
  for (Eigen::Index j = 0; j < dense.cols(); ++j)
    if (dense.col(j).cwiseAbs().maxCoeff() != 0.0) r.cols.push_back(static_cast<int>(j));
  r.v.resize(3, static_cast<Eigen::Index>(r.cols.size()));
  for (std::size_t k = 0; k < r.cols.size(); ++k) r.v.col(static_cast<Eigen::Index>(k)) = dense.col(r.cols[k]);
  return r;
}

Vector3d ScoleNonlinear::Rows3::times(const VectorXd& x) const {
  Vector3d out = Vector3d::Zero();
  for (std::size_t k = 0; k < cols.size(); ++k) out += v.col(static_cast<Eigen::Index>(k)) * x[cols[k]];
  return out;
}

void ScoleNonlinear::Rows3::add_transposed(const Vector3d& w, VectorXd& out) const {
  for (std::size_t k = 0; k < cols.size(); ++k) out[cols[k]] += v.col(static_cast<Eigen::Index>(k)).dot(w);
}

void ScoleNonlinear::Rows3::add_left(const Matrix3d& A, MatrixXd& out) const {
  for (std::size_t k = 0; k < cols.size(); ++k) out.col(cols[k]) += A * v.col(static_cast<Eigen::Index>(k));
}

namespace {
// x on the columns cols, in their order.
VectorXd gather_cols(const std::vector<int>& cols, const VectorXd& x) {
  VectorXd g(static_cast<Eigen::Index>(cols.size()));
  for (std::size_t k = 0; k < cols.size(); ++k) g[static_cast<Eigen::Index>(k)] = x[cols[k]];
  return g;
}
}  // namespace

VectorXd ScoleNonlinear::Kinematics::gather(const VectorXd& x) const { return gather_cols(cols, x); }

ScoleNonlinear::Kinematics::At ScoleNonlinear::Kinematics::at(const VectorXd& e, const TurnedRotation* turned,
                                                              bool third) const {
  At m;
  m.k = this;
  m.g = gather(e);
  const VectorXd& g = m.g;
  m.offset.setZero();
  m.J = N;
  if (A.cols() != 0) {
    const Vector3d Ag = A * g, Bg = B * g;
    m.offset += Ag.cross(Bg);
    m.J += skew(Ag) * B - skew(Bg) * A;
  }
  if (axial()) {
    const VectorXd Pg = P * g;
    m.Qg = P.transpose() * Pg;
    m.offset += 0.5 * Pg.squaredNorm() * t;
    m.J += t * m.Qg.transpose();
  }
  if (Theta.cols() != 0) {
    const Vector3d th = Theta * g;
    m.turned = (turned ? *turned : turned_rotation(th, third)).arm(arm);
    m.offset += m.turned.value - arm - th.cross(arm);
    m.J += (m.turned.d1 + skew(arm)) * Theta;
  }
  return m;
}

Vector3d ScoleNonlinear::Kinematics::At::rows(const VectorXd& y) const {
  return (J - k->N) * k->gather(y);
}

void ScoleNonlinear::Kinematics::At::rows_t(const Vector3d& w, VectorXd& out) const {
  const VectorXd v = (J - k->N).transpose() * w;
  for (std::size_t c = 0; c < k->cols.size(); ++c) out[k->cols[c]] += v[static_cast<Eigen::Index>(c)];
}

Vector3d ScoleNonlinear::Kinematics::At::convective(const VectorXd& x) const {
  const VectorXd gx = k->gather(x);
  Vector3d r = Vector3d::Zero();
  if (k->A.cols() != 0) r += 2.0 * Vector3d(k->A * gx).cross(k->B * gx);
  if (k->axial()) r += (k->P * gx).squaredNorm() * k->t;
  if (k->Theta.cols() != 0) {
    const Vector3d a = k->Theta * gx;
    r += turned.second(a, a);
  }
  return r;
}

void ScoleNonlinear::Kinematics::At::second_t(const VectorXd& y, const Vector3d& w, VectorXd& out, VectorXd* axial) const {
  const VectorXd gy = k->gather(y);
  VectorXd v = VectorXd::Zero(gy.size());
  if (k->A.cols() != 0) v += k->B.transpose() * w.cross(k->A * gy) + k->A.transpose() * Vector3d(k->B * gy).cross(w);
  if (k->axial()) {
    if (axial)
      *axial += k->t.dot(w) * gy;
    else
      v += k->t.dot(w) * (k->P.transpose() * (k->P * gy));
  }
  if (k->Theta.cols() != 0) v += k->Theta.transpose() * turned.second_t(k->Theta * gy, w);
  for (std::size_t c = 0; c < k->cols.size(); ++c) out[k->cols[c]] += v[static_cast<Eigen::Index>(c)];
}

void ScoleNonlinear::Kinematics::add_axial(const VectorXd& z, VectorXd& out) const {
  const VectorXd v = P.transpose() * (P * z);
  for (std::size_t c = 0; c < cols.size(); ++c) out[cols[c]] += v[static_cast<Eigen::Index>(c)];
}

void ScoleNonlinear::Kinematics::At::convective_t(const VectorXd& x, const Vector3d& w, VectorXd& out) const {
  if (k->Theta.cols() == 0) return;
  if (!turned.has_third) throw std::logic_error("Kinematics::At::convective_t: evaluated without third derivatives");
  const VectorXd v = k->Theta.transpose() * turned.third_t(k->Theta * k->gather(x), w);
  for (std::size_t c = 0; c < k->cols.size(); ++c) out[k->cols[c]] += v[static_cast<Eigen::Index>(c)];
}

Vector3d ScoleNonlinear::Rotor::tilt(const VectorXd& x) const {
  Vector3d p = th.times(x);
  p[2] = 0.0;
  return p;
}

Eigen::Matrix<double, 3, Eigen::Dynamic> ScoleNonlinear::Rotor::jacobian(const VectorXd& e) const {
  return th.v + skew(tilt(e)) * half;
}

namespace {
Matrix3d first_turn0(const Matrix3d& J, const Vector3d& v) {
  const Matrix3d VJ = skew(v) * J;
  return VJ + VJ.transpose();
}
}  // namespace

// A rotor's inertia turned by the section's rotation, J(θ) = R J Rᵀ to second order in θ = Θ e.
// The section turns as R = exp[α]× exp[ψ a]× (tilt, then twist about the axis a = ẑ; §3.8), whose
// rotation vector is φ = θ + ½ α × ψ a + O(θ³) (Baker–Campbell–Hausdorff), α = P⊥ θ, ψ a = P_z θ.
// With T = [θ]× and J₁(v) = [v]× J − J [v]×:
//   J(θ) = J + J₁(θ) + ½ (T² J + J T²) − T J T + J₁(½ α × ψ a) + O(θ³)      (symmetric)
// — quadratic in θ. Its second-order part carries the centrifugal stiffness of a body turned in a
// spinning frame: ½ Ωᵀ J(θ) Ω changes at second order in θ (a roll slew that turns an anisotropic
// body about pitch trades I_xx for I_zz), which a first-order J(θ) cannot give.
// J_k = J₁(e_k); J_kl from the second-order terms (E_k = [e_k]×):
// J_kl = ½ ((E_k E_l + E_l E_k) J + J (E_k E_l + E_l E_k)) − E_k J E_l − E_l J E_k
//        + J₁(½ (P⊥ e_k × P_z e_l + P⊥ e_l × P_z e_k)).
ScoleNonlinear::Turning::Turning(const Matrix3d& J) {
  for (int k = 0; k < 3; ++k) {
    const Vector3d ek = Vector3d::Unit(k);
    first[static_cast<std::size_t>(k)] = first_turn0(J, ek);
    for (int l = 0; l < 3; ++l) {
      const Vector3d el = Vector3d::Unit(l);
      const Matrix3d Ek = skew(ek), El = skew(el), S = Ek * El + El * Ek, EkJEl = Ek * J * El;
      const Vector3d bch = 0.5 * (Vector3d(ek[0], ek[1], 0.0).cross(Vector3d(0.0, 0.0, el[2])) +
                                  Vector3d(el[0], el[1], 0.0).cross(Vector3d(0.0, 0.0, ek[2])));
      second[static_cast<std::size_t>(k)][static_cast<std::size_t>(l)] =
          0.5 * (S * J + J * S) - EkJEl - EkJEl.transpose() + first_turn0(J, bch);
    }
  }
}

std::array<Matrix3d, 3> ScoleNonlinear::Turning::slopes(const Vector3d& theta) const {
  std::array<Matrix3d, 3> out;
  for (std::size_t k = 0; k < 3; ++k) {
    out[k] = first[k];
    for (std::size_t l = 0; l < 3; ++l) out[k] += theta[static_cast<Eigen::Index>(l)] * second[k][l];
  }
  return out;
}

Matrix3d ScoleNonlinear::Turning::change(const Vector3d& theta) const {
  Matrix3d d = Matrix3d::Zero();
  for (std::size_t k = 0; k < 3; ++k) {
    Matrix3d row = first[k];
    for (std::size_t l = 0; l < 3; ++l) row += 0.5 * theta[static_cast<Eigen::Index>(l)] * second[k][l];
    d += theta[static_cast<Eigen::Index>(k)] * row;
  }
  return d;
}

Vector3d ScoleNonlinear::Turning::curvature(const Vector3d& u, const Vector3d& a, const Vector3d& b) const {
  Vector3d g;
  for (std::size_t k = 0; k < 3; ++k) {
    Matrix3d Ck = Matrix3d::Zero();
    for (std::size_t l = 0; l < 3; ++l) Ck += u[static_cast<Eigen::Index>(l)] * second[k][l];
    g[static_cast<Eigen::Index>(k)] = a.dot(Ck * b);
  }
  return g;
}

namespace {
// The columns any of the dense rows (or P's) touch, and the rows restricted to them.
void compact(const std::vector<const MatrixXd*>& dense, const MatrixXd& Pfull, std::vector<int>& cols,
             std::vector<char>& local, std::vector<Eigen::Matrix<double, 3, Eigen::Dynamic>*> out, SparseMatrix& P) {
  const Eigen::Index ne = dense.front()->cols();
  cols.clear();
  local.clear();
  for (Eigen::Index j = 0; j < ne; ++j) {
    bool rows = false;
    for (const MatrixXd* d : dense) rows = rows || d->col(j).cwiseAbs().maxCoeff() != 0.0;
    if (rows || (Pfull.size() != 0 && Pfull.col(j).cwiseAbs().maxCoeff() != 0.0)) {
      cols.push_back(static_cast<int>(j));
      local.push_back(rows ? 1 : 0);
    }
  }
  const auto k = static_cast<Eigen::Index>(cols.size());
  for (std::size_t i = 0; i < dense.size(); ++i) {
    out[i]->resize(3, k);
    for (Eigen::Index c = 0; c < k; ++c) out[i]->col(c) = dense[i]->col(cols[static_cast<std::size_t>(c)]);
  }
  if (Pfull.size() != 0) {
    MatrixXd Pc(Pfull.rows(), k);
    for (Eigen::Index c = 0; c < k; ++c) Pc.col(c) = Pfull.col(cols[static_cast<std::size_t>(c)]);
    P = Pc.sparseView();
  }
}
}  // namespace

namespace {
// Gauss–Legendre rules on [0, 1]: four points (degree 7) and three (degree 5).
struct GaussRules {
  double x4[4], w4[4], x3[3], w3[3];
  GaussRules() {
    const double a4 = std::sqrt(3.0 / 7.0 - 2.0 / 7.0 * std::sqrt(1.2)), b4 = std::sqrt(3.0 / 7.0 + 2.0 / 7.0 * std::sqrt(1.2));
    const double wa = (18.0 + std::sqrt(30.0)) / 36.0, wb = (18.0 - std::sqrt(30.0)) / 36.0;
    const double x4v[4] = {0.5 * (1 - b4), 0.5 * (1 - a4), 0.5 * (1 + a4), 0.5 * (1 + b4)};
    const double w4v[4] = {0.5 * wb, 0.5 * wa, 0.5 * wa, 0.5 * wb};
    const double g3 = 0.5 * std::sqrt(0.6);
    const double x3v[3] = {0.5 - g3, 0.5, 0.5 + g3}, w3v[3] = {5.0 / 18.0, 8.0 / 18.0, 5.0 / 18.0};
    std::copy(x4v, x4v + 4, x4);
    std::copy(w4v, w4v + 4, w4);
    std::copy(x3v, x3v + 3, x3);
    std::copy(w3v, w3v + 3, w3);
  }
};
const GaussRules kGauss;

// The mast's point at arc length s from its root (it runs along −z).
Vector3d mast_point(const io::ScoleSpec& sc, double s) { return Vector3d(vec3(sc.mast_root) - s * Vector3d::UnitZ()); }
}  // namespace

MatrixXd ScoleNonlinear::on_e(const MatrixXd& rows) const { return MatrixXd(rows.leftCols(ne_)); }

ScoleNonlinear::ScoleNonlinear(const ScoleFE& fe, const std::vector<io::InputSpec>& inputs,
                               const std::vector<io::SensorSpec>& sensors) {
  const StructuralModel& m = fe.model;
  const int n = m.ndof;
  ne_ = n - 6;
  ncoef_ = m.ncoef;
  for (int i = 0; i < 6; ++i)
    if (fe.shuttle_dof(i) != ne_ + i) throw std::logic_error("ScoleNonlinear: the shuttle DOFs must come last");
  if (inputs.size() != m.inputs.size() || sensors.size() != m.sensors.size())
    throw std::logic_error("ScoleNonlinear: inputs and sensors must be the linear model's");

  G_ = MatrixXd::Zero(n, 6 + ne_);
  for (int k = 0; k < 3; ++k) {
    G_.col(k) = fe.rigid_motion(Vector3d::Unit(k), Vector3d::Zero());
    G_.col(3 + k) = fe.rigid_motion(Vector3d::Zero(), Vector3d::Unit(k));
  }
  G_.block(0, 6, ne_, ne_).setIdentity();

  add_mast(fe);
  add_foreshortening(fe);
  add_reflector(fe);
  add_shuttle_and_proof_masses(fe);
  index_points();
  for (const auto& t : m.stiffness) stiffness_.push_back({SparseMatrix(t.matrix.topLeftCorner(ne_, ne_)), t.coefficient});
  for (const auto& t : m.damping) damping_.push_back({SparseMatrix(t.matrix.topLeftCorner(ne_, ne_)), t.coefficient});
  add_inputs(fe, inputs);
  add_sensors(fe, sensors);
}

// Mast: ρA at four Gauss points per element (degree 7: exact for products of Hermite cubics),
// ρI_ψ at three (degree 5: exact for the slopes' and the linear twist's products).
void ScoleNonlinear::add_mast(const ScoleFE& fe) {
  const io::ScoleSpec& sc = fe.spec;
  const double h = sc.length / fe.elements;
  const auto& [x4, w4, x3, w3] = kGauss;
  const double bend = sc.bending_rotary_inertia ? 0.5 : 0.0;
  for (int el = 0; el < fe.elements; ++el) {
    for (int q = 0; q < 4; ++q) {
      const double s = (el + x4[q]) * h;
      points_.push_back({mast_point(sc, s), on_e(fe.mast_displacement(s)), w4[q] * h, ScoleFE::kRhoA, {}, {}});
    }
    for (int q = 0; q < 3; ++q) {
      const double s = (el + x3[q]) * h;
      rotors_.push_back({w3[q] * h * Vector3d(bend, bend, 1.0).asDiagonal().toDenseMatrix(), on_e(fe.mast_rotation(s)),
                         ScoleFE::kRhoIPsi, {}, {}, {}});
    }
    // The strain energy's higher-order rows at four Gauss points (degree 7: W₄'s density has degree
    // 6 in s on an element). The rotation rows are polynomials of degree ≤ 2 in s there (Hermite
    // slopes, linear twist), so a central difference inside the element is their exact derivative.
    for (int q = 0; q < 4; ++q) {
      const double s = (el + x4[q]) * h, ds = 0.05 * h;
      MatrixXd rows(6, ne_);
      rows.topRows(3) = on_e(fe.mast_rotation(s));
      rows.bottomRows(3) = (on_e(fe.mast_rotation(s + ds)) - on_e(fe.mast_rotation(s - ds))) / (2.0 * ds);
      Coupling c;
      for (Eigen::Index j = 0; j < ne_; ++j)
        if (rows.col(j).cwiseAbs().maxCoeff() != 0.0) c.cols.push_back(static_cast<int>(j));
      c.rows.resize(6, static_cast<Eigen::Index>(c.cols.size()));
      for (std::size_t k = 0; k < c.cols.size(); ++k) c.rows.col(static_cast<Eigen::Index>(k)) = rows.col(c.cols[k]);
      c.weight = w4[q] * h;
      coupling_.push_back(std::move(c));
    }
  }
}

// The mast's foreshortening (struct Foreshortening): the slopes' rows at three Gauss points per
// element and, per mast mass point, at three on [element start, s_i].
void ScoleNonlinear::add_foreshortening(const ScoleFE& fe) {
  const double h = fe.spec.length / fe.elements;
  const auto& [x4, w4, x3, w3] = kGauss;
  auto node = [&](double s, double weight) {
    Foreshortening::Node nd;
    const MatrixXd R = on_e(fe.mast_rotation(s)).topRows(2);
    for (Eigen::Index j = 0; j < ne_; ++j)
      if (R.col(j).cwiseAbs().maxCoeff() != 0.0) nd.cols.push_back(static_cast<int>(j));
    nd.rows.resize(2, static_cast<Eigen::Index>(nd.cols.size()));
    for (std::size_t k = 0; k < nd.cols.size(); ++k) nd.rows.col(static_cast<Eigen::Index>(k)) = R.col(nd.cols[k]);
    nd.weight = weight;
    return nd;
  };
  fs_.elements = fe.elements;
  for (int el = 0; el < fe.elements; ++el)
    for (int q = 0; q < 3; ++q) fs_.node.push_back(node((el + x3[q]) * h, w3[q] * h));
  for (int el = 0; el < fe.elements; ++el)
    for (int q = 0; q < 4; ++q) {
      const double s0 = el * h, len = x4[q] * h;
      for (int k = 0; k < 3; ++k) fs_.node.push_back(node(s0 + x3[k] * len, w3[k] * len));
      fs_.element_of.push_back(el);
      fs_.point.push_back(static_cast<std::size_t>(4 * el + q));
    }
  fs_.t = Vector3d::UnitZ();  // the mast runs along −z from its root
  for (std::size_t i : fs_.point)  // T_fs leaves M_ee alone only because the rows are lateral
    if ((fs_.t.transpose() * points_[i].N).cwiseAbs().maxCoeff() != 0.0)
      throw std::logic_error("ScoleNonlinear: a mast point's rows move it along the mast");
}

// Reflector: a rigid body on the mast's end, moving exactly with the end section. Every one of
// its points is the end's point turned by the section's rotation (turned_arm.h; the linear part
// Θ(L) e × a of an arm a is in the point's linear rows) and carried back towards the root by the
// end's foreshortening ½ ∫ (u_x'² + u_y'²) ds (an inextensible mast). Its CM carries its mass (its
// own coefficient); its inertia about the CM J is carried by pairs of points at ±d on the
// principal axes of the second moment S = ½ tr(J) I − J (J = tr(S) I − S), each pair of mass
// s_k / d² (s_k an eigenvalue of S: a pair gives s_k u_k u_kᵀ), their mass taken back at the CM
// (a constant offset of the CM point's mass).
// A rigid body's kinetic energy is fixed by its mass, CM and second moment, so this is the body's
// exactly, rotation and all (docs/theory.md §3.8).
void ScoleNonlinear::add_reflector(const ScoleFE& fe) {
  const io::ScoleSpec& sc = fe.spec;
  const double L = sc.length, h = L / fe.elements;
  const auto& [x4, w4, x3, w3] = kGauss;
  const Vector3d r(sc.reflector_rx, sc.reflector_ry, 0.0);
  const MatrixXd Th = on_e(fe.mast_rotation(L)), U = on_e(fe.mast_displacement(L));
  // Q = ∫ Θ⊥ᵀ Θ⊥ ds = Pᵀ P: three Gauss points per element (exact: degree 4).
  MatrixXd Pfull(6 * fe.elements, ne_);
  for (int el = 0; el < fe.elements; ++el)
    for (int q = 0; q < 3; ++q)
      Pfull.middleRows(6 * el + 2 * q, 2) = std::sqrt(w3[q] * h) * on_e(fe.mast_rotation((el + x3[q]) * h)).topRows(2);
  auto end_point = [&](const Vector3d& arm, double weight, int coefficient) {
    MassPoint pt{mast_point(sc, L) + arm, MatrixXd(U - skew(arm) * Th), weight, coefficient, {}, {}};
    compact({&pt.N, &Th}, Pfull, pt.kin.cols, pt.kin.local, {&pt.kin.N, &pt.kin.Theta}, pt.kin.P);
    pt.kin.arm = arm;
    pt.kin.t = Vector3d::UnitZ();  // unit: solve_mass's rank-2 form of the axial part needs |t| = 1
    points_.push_back(std::move(pt));
  };
  const std::size_t cm = points_.size();
  end_point(r, 1.0, ScoleFE::kMReflector);
  const Matrix3d J = inertia_matrix(sc.reflector);
  const Eigen::SelfAdjointEigenSolver<Matrix3d> S(0.5 * J.trace() * Matrix3d::Identity() - J);
  // d: the radius of gyration, so that the pairs weigh what the reflector does (any d > 0 is
  // exact). An inertia whose largest principal moment exceeds the sum of the other two (no rigid
  // body's: a flat one given products of inertia) has s_k < 0, a pair of negative mass: exact all
  // the same; M(e) stays positive definite wherever the inertia does (checked at e = 0 below).
  const double ssum = S.eigenvalues().cwiseAbs().sum();
  const double d = sc.reflector.mass > 0.0 && ssum > 0.0 ? std::sqrt(ssum / sc.reflector.mass) : 1.0;
  double taken = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double sk = S.eigenvalues()[k];
    if (std::abs(sk) <= 1e-12 * J.trace()) continue;  // a flat body has none along its normal
    const Vector3d dk = d * S.eigenvectors().col(k);
    end_point(r + dk, 0.5 * sk / (d * d), -1);
    end_point(r - dk, 0.5 * sk / (d * d), -1);
    taken += sk / (d * d);
  }
  points_[cm].offset = -taken;
}

// The shuttle (a rigid body at S's origin); the proof masses on their own lateral DOFs, axially
// with the mast.
void ScoleNonlinear::add_shuttle_and_proof_masses(const ScoleFE& fe) {
  const io::ScoleSpec& sc = fe.spec;
  points_.push_back({Vector3d::Zero(), MatrixXd::Zero(3, ne_), sc.shuttle.mass, -1, {}, {}});
  rotors_.push_back({inertia_matrix(sc.shuttle), MatrixXd::Zero(3, ne_), -1, {}, {}, {}});
  for (std::size_t k = 0; k < sc.actuator_locations.size(); ++k) {
    MatrixXd N = MatrixXd::Zero(3, ne_);
    N(0, fe.proof_mass_dof(static_cast<int>(k), 0)) = 1.0;
    N(1, fe.proof_mass_dof(static_cast<int>(k), 1)) = 1.0;
    // The slider plane turns with the section at s_k: r = p + N e + Θ(s_k) e × S e, S e the stroke
    // (ξ − u(s_k), 0) — a coupling of the bending slope and twist with the stroke.
    const double s = sc.actuator_locations[k];
    const MatrixXd Th = on_e(fe.mast_rotation(s));
    MatrixXd S = N - on_e(fe.mast_displacement(s));
    S.row(2).setZero();
    MassPoint pm{mast_point(sc, s), N, sc.actuator_mass, -1, {}, {}};
    compact({&N, &Th, &S}, MatrixXd(), pm.kin.cols, pm.kin.local, {&pm.kin.N, &pm.kin.A, &pm.kin.B}, pm.kin.P);
    points_.push_back(std::move(pm));
  }
}

// The compact rows of every point and rotor, and the points' axial groups (points sharing the
// same foreshortening rows share one representative).
void ScoleNonlinear::index_points() {
  for (auto& p : points_) p.n = Rows3::of(p.N);
  for (std::size_t i = 0; i < points_.size(); ++i) {
    auto& q = points_[i].kin;
    for (std::size_t a = 0; a < q.cols.size(); ++a)
      if (q.local[a]) q.local_index.push_back(static_cast<int>(a));
    if (!q.axial()) continue;
    for (std::size_t g = 0; g < axial_rep_.size() && q.axial_group < 0; ++g) {
      const auto& r = points_[axial_rep_[g]].kin;
      if (r.cols == q.cols && r.P.rows() == q.P.rows() && (r.P - q.P).norm() == 0.0) q.axial_group = static_cast<int>(g);
    }
    if (q.axial_group < 0) {
      q.axial_group = static_cast<int>(axial_rep_.size());
      axial_rep_.push_back(i);
    }
  }
  for (auto& r : rotors_) {
    r.th = Rows3::of(r.Theta);
    r.half = r.th.v;
    r.half.topRows<2>() *= 0.5;
    r.turn = Turning(r.J);
  }
}

// The reflector's CM is the point after the mast's (points_ is complete: addresses are stable).
const ScoleNonlinear::Kinematics* ScoleNonlinear::reflector_kinematics(const ScoleFE& fe) const {
  return &points_[static_cast<std::size_t>(4 * fe.elements)].kin;
}

void ScoleNonlinear::add_inputs(const ScoleFE& fe, const std::vector<io::InputSpec>& inputs) {
  const StructuralModel& m = fe.model;
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    const auto& spec = inputs[i];
    Input in;
    in.q0 = G_.transpose() * m.inputs[i].vector;
    in.coefficient = m.inputs[i].coefficient;
    if (spec.kind == io::InputKind::Force && (spec.at == io::Site::Mast || spec.at == io::Site::Reflector)) {
      in.arm = true;
      in.N = spec.at == io::Site::Mast ? on_e(fe.mast_displacement(spec.location)) : on_e(fe.reflector_displacement());
      in.d = vec3(spec.direction);
      if (spec.at == io::Site::Reflector) in.kin = reflector_kinematics(fe);
    }
    inputs_.push_back(std::move(in));
  }
}

void ScoleNonlinear::add_sensors(const ScoleFE& fe, const std::vector<io::SensorSpec>& sensors) {
  const io::ScoleSpec& sc = fe.spec;
  for (std::size_t k = 0; k < sensors.size(); ++k) {
    const auto& spec = sensors[k];
    const ModelSensor& ms = fe.model.sensors[k];
    using K = Sensor::Kind;
    Sensor s;
    s.d = vec3(spec.direction);
    if (spec.at == io::Site::Shuttle) {
      s.kind = spec.kind == io::SensorKind::Rotation       ? K::ShuttleRotation
               : spec.kind == io::SensorKind::Velocity     ? K::ShuttleVelocity
               : spec.kind == io::SensorKind::Acceleration ? K::ShuttleAcceleration
                                                           : K::ShuttleDisplacement;
    } else if (spec.kind == io::SensorKind::Acceleration) {
      s.kind = K::PointAcceleration;
      const bool mast = spec.at == io::Site::Mast;
      s.p = mast ? mast_point(sc, spec.location) : mast_point(sc, sc.length) + Vector3d(sc.reflector_rx, sc.reflector_ry, 0.0);
      s.N = mast ? on_e(fe.mast_displacement(spec.location)) : on_e(fe.reflector_displacement());
      if (!mast) s.kin = reflector_kinematics(fe);
    } else {
      // Relative to S: the linear rows restricted to e (they vanish on rigid motion).
      s.kind = ms.order == 1 ? K::RateRow : K::Row;
      s.row = ms.row.head(ne_);
    }
    sensors_.push_back(std::move(s));
    sensor_names_.push_back(ms.name);
  }
}

ScoleNonlinear::Foreshortening::Slopes ScoleNonlinear::Foreshortening::slopes(const VectorXd& x) const {
  Slopes S(2, static_cast<Eigen::Index>(node.size()));
  for (std::size_t j = 0; j < node.size(); ++j) {
    const Node& nd = node[j];
    Eigen::Vector2d a = Eigen::Vector2d::Zero();
    for (std::size_t k = 0; k < nd.cols.size(); ++k) a += nd.rows.col(static_cast<Eigen::Index>(k)) * x[nd.cols[k]];
    S.col(static_cast<Eigen::Index>(j)) = a;
  }
  return S;
}

void ScoleNonlinear::Foreshortening::add(std::size_t j, const Eigen::Vector2d& a, VectorXd& out) const {
  const Node& nd = node[j];
  for (std::size_t k = 0; k < nd.cols.size(); ++k) out[nd.cols[k]] += nd.rows.col(static_cast<Eigen::Index>(k)).dot(a);
}

void ScoleNonlinear::Foreshortening::forms(const Slopes& X, const Slopes& Y, std::vector<double>& out) const {
  auto form = [&](std::size_t j) {
    const auto jj = static_cast<Eigen::Index>(j);
    return node[j].weight * X.col(jj).dot(Y.col(jj));
  };
  out.assign(size(), 0.0);
  double below = 0.0;  // over the elements below the current one
  int el = 0;
  const std::size_t first_partial = 3 * static_cast<std::size_t>(elements);
  for (std::size_t i = 0; i < size(); ++i) {
    for (; el < element_of[i]; ++el)
      for (std::size_t q = 0; q < 3; ++q) below += form(3 * static_cast<std::size_t>(el) + q);
    double v = below;
    for (std::size_t q = 0; q < 3; ++q) v += form(first_partial + 3 * i + q);
    out[i] = v;
  }
}

template <class G, class Visit>
void ScoleNonlinear::Foreshortening::coefficients(const std::vector<G>& gamma, G zero, Visit&& visit) const {
  const std::size_t first_partial = 3 * static_cast<std::size_t>(elements);
  G above = zero;
  std::size_t i = size();
  for (int el = elements - 1; el >= 0; --el) {
    for (std::size_t q = 0; q < 3; ++q) visit(3 * static_cast<std::size_t>(el) + q, above);
    for (; i > 0 && element_of[i - 1] == el; --i) {
      for (std::size_t q = 0; q < 3; ++q) visit(first_partial + 3 * (i - 1) + q, gamma[i - 1]);
      above += gamma[i - 1];
    }
  }
}

void ScoleNonlinear::Foreshortening::apply(const std::vector<double>& gamma, const Slopes& X, VectorXd& out) const {
  coefficients(gamma, 0.0, [&](std::size_t j, double c) {
    if (c != 0.0) add(j, Eigen::Vector2d(c * node[j].weight * X.col(static_cast<Eigen::Index>(j))), out);
  });
}

void ScoleNonlinear::Foreshortening::apply_rows(const std::vector<Eigen::Matrix<double, 6, 1>>& gamma, const Slopes& X,
                                                MatrixXd& out) const {
  using Vector6 = Eigen::Matrix<double, 6, 1>;
  coefficients(gamma, Vector6::Zero().eval(), [&](std::size_t j, const Vector6& g) {
    const Node& nd = node[j];
    const Eigen::Vector2d a = nd.weight * X.col(static_cast<Eigen::Index>(j));
    for (std::size_t k = 0; k < nd.cols.size(); ++k) out.col(nd.cols[k]) += g * nd.rows.col(static_cast<Eigen::Index>(k)).dot(a);
  });
}

ScoleNonlinear::Dynamics ScoleNonlinear::at(const VectorXd& c, double constants) const {
  if (c.size() != ncoef_) throw std::invalid_argument("ScoleNonlinear::at: coefficient vector of the wrong size");
  Dynamics d;
  d.g_ = this;
  d.constants_ = constants;
  auto scale = [&](int k) { return k >= 0 ? c[k] : constants; };
  const int nu = speeds();
  d.Mconst_ = MatrixXd::Zero(nu, nu);
  for (const auto& p : points_) {
    const double mi = p.weight * scale(p.coefficient) + p.offset * constants;
    d.mass_.push_back(mi);
    d.Mconst_.block<3, 3>(0, 0) += mi * Matrix3d::Identity();
    if (p.kin.active()) {  // its rows on e depend on e (kinematics())
      d.e_dependent_ = true;
      continue;
    }
    d.Mconst_.block(0, 6, 3, ne_) += mi * p.N;
    d.Mconst_.block(6, 6, ne_, ne_) += mi * p.N.transpose() * p.N;
  }
  for (const auto& r : rotors_) {
    const Matrix3d J = r.J * scale(r.coefficient);
    d.J_.push_back(J);
    d.rotor_scale_.push_back(scale(r.coefficient));
    if (!r.th.cols.empty()) d.e_dependent_ = true;  // its inertia turns with e
    d.Mconst_.block<3, 3>(3, 3) += J;
    d.Mconst_.block(3, 6, 3, ne_) += J * r.Theta;
    d.Mconst_.block(6, 6, ne_, ne_) += r.Theta.transpose() * J * r.Theta;
  }
  d.Mconst_.block(6, 0, ne_, 3) = d.Mconst_.block(0, 6, 3, ne_).transpose();
  d.Mconst_.block(6, 3, ne_, 3) = d.Mconst_.block(3, 6, 3, ne_).transpose();
  for (const auto& in : inputs_) d.input_scale_.push_back(in.coefficient >= 0 ? c[in.coefficient] : 1.0);
  {
    std::vector<Eigen::Triplet<double>> t;
    for (Eigen::Index j = 0; j < ne_; ++j)
      for (Eigen::Index i = 0; i < ne_; ++i)
        if (d.Mconst_(6 + i, 6 + j) != 0.0) t.emplace_back(i, j, d.Mconst_(6 + i, 6 + j));
    for (const auto& r : rotors_)  // a turned rotor couples all of its columns
      for (int a : r.th.cols)
        for (int b : r.th.cols) t.emplace_back(a, b, 0.0);
    for (const auto& p : points_)  // the nonlinear points' local pattern, explicitly
      for (std::size_t a = 0; a < p.kin.cols.size(); ++a)
        for (std::size_t b = 0; b < p.kin.cols.size(); ++b)
          if (p.kin.local[a] && p.kin.local[b]) t.emplace_back(p.kin.cols[a], p.kin.cols[b], 0.0);
    d.Cbase_.resize(ne_, ne_);
    d.Cbase_.setFromTriplets(t.begin(), t.end());
    d.Cbase_.makeCompressed();
    auto slot = [&](int i, int j) {
      const int* first = d.Cbase_.innerIndexPtr() + d.Cbase_.outerIndexPtr()[j];
      const int* last = d.Cbase_.innerIndexPtr() + d.Cbase_.outerIndexPtr()[j + 1];
      const int* it = std::lower_bound(first, last, i);
      if (it == last || *it != i) throw std::logic_error("ScoleNonlinear: an entry outside the mass pattern");
      return static_cast<int>(it - d.Cbase_.innerIndexPtr());
    };
    for (const auto& r : rotors_) {
      std::vector<int> sl;
      for (int a : r.th.cols)
        for (int b : r.th.cols) sl.push_back(slot(a, b));
      d.rotor_slots_.push_back(std::move(sl));
    }
    for (const auto& p : points_) {
      std::vector<int> sl;
      for (std::size_t a = 0; a < p.kin.cols.size(); ++a)
        for (std::size_t b = 0; b < p.kin.cols.size(); ++b)
          sl.push_back(p.kin.local[a] && p.kin.local[b] ? slot(p.kin.cols[a], p.kin.cols[b]) : -1);
      d.point_slots_.push_back(std::move(sl));
    }
    auto C = std::make_shared<Eigen::SimplicialLLT<SparseMatrix>>();
    if (d.e_dependent_) {
      // Checked positive definite at e = 0 here; per e, solve_mass factorises and reports failure.
      SparseMatrix C0 = d.Cbase_;
      for (std::size_t i = 0; i < points_.size(); ++i) {
        const auto& q = points_[i].kin;
        if (!q.active()) continue;
        const MatrixXd Mi = d.mass_[i] * q.N.transpose() * q.N;  // N(0) = N: local columns only
        for (std::size_t a = 0; a < q.cols.size(); ++a)
          for (std::size_t b = 0; b < q.cols.size(); ++b)
            if (q.local[a] && q.local[b])
              C0.coeffRef(q.cols[a], q.cols[b]) += Mi(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(b));
      }
      C->compute(C0);
    } else {
      C->compute(d.Cbase_);
    }
    if (C->info() != Eigen::Success)
      throw std::invalid_argument("ScoleNonlinear::at: the elastic mass block is not positive definite");
    d.C_ = C;
  }
  d.K_ = MatrixXd::Zero(ne_, ne_);
  d.D_ = MatrixXd::Zero(ne_, ne_);
  for (const auto& t : stiffness_) d.K_ += scale(t.coefficient) * MatrixXd(t.matrix);
  for (const auto& t : damping_) d.D_ += scale(t.coefficient) * MatrixXd(t.matrix);
  d.k_roll_ = scale(ScoleFE::kEIRoll);
  d.k_pitch_ = scale(ScoleFE::kEIPitch);
  d.k_twist_ = scale(ScoleFE::kGJ);
  return d;
}

namespace {
using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

// The strain energy's density beyond the quadratic, W₃ + W₄ (struct Coupling), at
// a = (x, y, z, X, Y, Z) = (θ_x, θ_y, θ_z, θ_x', θ_y', θ_z'), with c1 = EI_roll, c2 = EI_pitch, g = GJ,
// d = x X + y Y, q = x Y − y X:
//   W₃ = −½ g Z q + (c1 − c2) z X Y
//   W₄ = ½ [(c1 x X + c2 y Y) d + (c1 − c2) z² (Y² − X²) + ¼ g q²]
// Value, gradient and Hessian (every term a product of the six values: closed form).
struct Density {
  double value = 0;
  Vector6d grad = Vector6d::Zero();
  Matrix6d hess = Matrix6d::Zero();
};

Density strain_density(const Vector6d& a, double c1, double c2, double g, bool hessian) {
  const double x = a[0], y = a[1], z = a[2], X = a[3], Y = a[4], Z = a[5];
  const double d = x * X + y * Y, q = x * Y - y * X, b = c1 - c2, w = c1 * x * X + c2 * y * Y;
  Vector6d gd, gq, gw, gz;
  gd << X, Y, 0, x, y, 0;
  gq << Y, -X, 0, -y, x, 0;
  gw << c1 * X, c2 * Y, 0, c1 * x, c2 * y, 0;
  const double v = Y * Y - X * X;  // z² v in W₄
  gz << 0, 0, 2 * z * v, -2 * z * z * X, 2 * z * z * Y, 0;
  Density D;
  D.value = -0.5 * g * Z * q + b * z * X * Y + 0.5 * (w * d + b * z * z * v + 0.25 * g * q * q);
  Vector6d g3;
  g3 << 0, 0, b * X * Y, b * z * Y, b * z * X, 0;
  D.grad = -0.5 * g * (Z * gq) + g3 + 0.5 * (gw * d + w * gd + b * gz + 0.5 * g * q * gq);
  D.grad[5] += -0.5 * g * q;
  if (!hessian) return D;
  Matrix6d H = Matrix6d::Zero();
  auto add = [&](int i, int j, double val) {
    H(i, j) += val;
    if (i != j) H(j, i) += val;
  };
  // W₃: −½ g Z q (q's Hessian: (0,4) = 1, (1,3) = −1) and b z X Y.
  for (int k = 0; k < 6; ++k) add(5, k, -0.5 * g * gq[k] * (k == 5 ? 0.5 : 1.0));
  add(0, 4, -0.5 * g * Z);
  add(1, 3, 0.5 * g * Z);
  add(2, 3, b * Y);
  add(2, 4, b * X);
  add(3, 4, b * z);
  // W₄: ½ [gw gdᵀ + gd gwᵀ + d ∇²w + w ∇²d + b ∇²(z² v) + ¼ g (2 gq gqᵀ + 2 q ∇²q)].
  H += 0.5 * (gw * gd.transpose() + gd * gw.transpose()) + 0.25 * g * gq * gq.transpose();
  add(0, 3, 0.5 * (d * c1 + w));
  add(1, 4, 0.5 * (d * c2 + w));
  add(2, 2, 0.5 * b * 2 * v);
  add(2, 3, 0.5 * b * (-4 * z * X));
  add(2, 4, 0.5 * b * (4 * z * Y));
  add(3, 3, 0.5 * b * (-2 * z * z));
  add(4, 4, 0.5 * b * (2 * z * z));
  add(0, 4, 0.25 * g * q);
  add(1, 3, -0.25 * g * q);
  D.hess = H;
  return D;
}

template <class C>
Vector6d coupling_values(const C& c, const VectorXd& x) {
  Vector6d a = Vector6d::Zero();
  for (std::size_t k = 0; k < c.cols.size(); ++k) a += c.rows.col(static_cast<Eigen::Index>(k)) * x[c.cols[k]];
  return a;
}
template <class C>
void coupling_add(const C& c, const Vector6d& g, VectorXd& out) {
  for (std::size_t k = 0; k < c.cols.size(); ++k) out[c.cols[k]] += c.rows.col(static_cast<Eigen::Index>(k)).dot(g);
}
}  // namespace

double ScoleNonlinear::Dynamics::coupling_energy(const VectorXd& e) const {
  double W = 0.0;
  for (const auto& c : g_->coupling_) W += c.weight * strain_density(coupling_values(c, e), k_roll_, k_pitch_, k_twist_, false).value;
  return W;
}

void ScoleNonlinear::Dynamics::add_coupling_force(const VectorXd& e, VectorXd& out) const {
  for (const auto& c : g_->coupling_)
    coupling_add(c, c.weight * strain_density(coupling_values(c, e), k_roll_, k_pitch_, k_twist_, false).grad, out);
}

void ScoleNonlinear::Dynamics::add_coupling_hessian(const VectorXd& e, const VectorXd& x, VectorXd& out) const {
  for (const auto& c : g_->coupling_)
    coupling_add(c, c.weight * (strain_density(coupling_values(c, e), k_roll_, k_pitch_, k_twist_, true).hess * coupling_values(c, x)),
                 out);
}

void ScoleNonlinear::Dynamics::add_coupling_coefficients(const VectorXd& e, const VectorXd& mu, VectorXd& dc) const {
  // The density is linear in (EI_roll, EI_pitch, GJ): its gradient at unit coefficients.
  for (const auto& c : g_->coupling_) {
    const Vector6d a = coupling_values(c, e), m = coupling_values(c, mu);
    dc[ScoleFE::kEIRoll] += c.weight * strain_density(a, 1.0, 0.0, 0.0, false).grad.dot(m);
    dc[ScoleFE::kEIPitch] += c.weight * strain_density(a, 0.0, 1.0, 0.0, false).grad.dot(m);
    dc[ScoleFE::kGJ] += c.weight * strain_density(a, 0.0, 0.0, 1.0, false).grad.dot(m);
  }
}

std::vector<ScoleNonlinear::Kinematics::At> ScoleNonlinear::Dynamics::kinematics(const VectorXd& e, bool third) const {
  std::vector<Kinematics::At> K(g_->points_.size());
  if (!e_dependent_) return K;
  // The reflector's points share the end section's rotation: one R(θ) for consecutive points at
  // the same θ.
  TurnedRotation R;
  Vector3d last = Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  for (std::size_t i = 0; i < g_->points_.size(); ++i) {
    const auto& q = g_->points_[i].kin;
    if (!q.active()) continue;
    if (q.Theta.cols() == 0) {
      K[i] = q.at(e);
      continue;
    }
    const Vector3d th = q.Theta * q.gather(e);
    if (th != last) {
      R = turned_rotation(th, third);
      last = th;
    }
    K[i] = q.at(e, &R);
  }
  return K;
}

namespace {
// P⊥ v: Aᵀ w = Θᵀ P⊥ w (the tilt's rows are Θ's first two).
Vector3d tilt_of(const Vector3d& v) { return {v[0], v[1], 0.0}; }

// out.col(cols[k]) += A Je.col(k)
void add_left_compact(const std::vector<int>& cols, const Matrix3d& A, const Eigen::Matrix<double, 3, Eigen::Dynamic>& Je,
                      MatrixXd& out) {
  for (std::size_t k = 0; k < cols.size(); ++k) out.col(cols[k]) += A * Je.col(static_cast<Eigen::Index>(k));
}
}  // namespace

void ScoleNonlinear::Dynamics::rigid_rows(const VectorXd& e, const std::vector<Kinematics::At>& kin,
                                          Eigen::Matrix<double, 6, 6>& A, MatrixXd& B) const {
  const int ne = g_->ne_;
  A = Mconst_.topLeftCorner<6, 6>();
  B = Mconst_.block(0, 6, 6, ne);
  Matrix3d VO = Matrix3d::Zero(), OO = Matrix3d::Zero();
  MatrixXd Oe = MatrixXd::Zero(3, ne);
  for (std::size_t i = 0; i < g_->points_.size(); ++i) {
    const auto& p = g_->points_[i];
    const double mi = mass_[i];
    if (mi == 0.0) continue;
    if (p.kin.active()) {
      const auto& Je = kin[i].J;
      const Matrix3d Rx = skew(p.p + p.n.times(e) + kin[i].offset);
      VO -= mi * Rx;
      OO += mi * Rx.transpose() * Rx;
      for (std::size_t k = 0; k < p.kin.cols.size(); ++k) B.col(p.kin.cols[k]).head<3>() += mi * Je.col(static_cast<Eigen::Index>(k));
      add_left_compact(p.kin.cols, mi * Rx, Je, Oe);
      continue;
    }
    const Matrix3d Rx = skew(p.p + p.n.times(e));
    VO -= mi * Rx;
    OO += mi * Rx.transpose() * Rx;
    p.n.add_left(mi * Rx, Oe);
  }
  for (std::size_t j = 0; j < g_->rotors_.size(); ++j) {
    const auto& rt = g_->rotors_[j];
    if (rt.th.cols.empty()) continue;
    const Matrix3d dJ = rotor_scale_[j] * rt.turn.change(rt.th.times(e));
    OO += dJ;
    // J(θ) Θ(e) − J Θ = ΔJ Θ + J(θ) [p]× B (the constant part is in Mconst_)
    const Matrix3d X = dJ, Y = (J_[j] + dJ) * skew(rt.tilt(e));
    for (std::size_t k = 0; k < rt.th.cols.size(); ++k) {
      const auto kk = static_cast<Eigen::Index>(k);
      Oe.col(rt.th.cols[k]) += X * rt.th.v.col(kk) + Y * rt.half.col(kk);
    }
  }
  A.block<3, 3>(0, 3) += VO;
  A.block<3, 3>(3, 0) += VO.transpose();
  A.block<3, 3>(3, 3) += OO;
  B.bottomRows<3>() += Oe;
  add_foreshortening_rows(e, A, B);
}

// T_fs = Σ m k·s, k = V + Ω × r + N ė the point's velocity without its shift (r = p + N e),
// s = t ẇ + (Ω × t) w the shift's (w = ½ eᵀ Q e, g = Q e). As t·N = 0 (the mast's rows are
// lateral), T_fs = ½ uᵀ M_fs u with
//   M_Ve = m t gᵀ,  M_Ωe = m [(r × t) gᵀ + w [t]× N],  M_VΩ = −m w [t]×,
//   M_ΩΩ = −m w ([r]×[t]× + [t]×[r]×);   the axial inertia's m g gᵀ on M_ee is applied in
// axial_inertia_solve (dense); ½ m w² |Ω × t|² is left out (struct Foreshortening).
void ScoleNonlinear::Dynamics::add_foreshortening_rows(const VectorXd& e, Eigen::Matrix<double, 6, 6>& A,
                                                       MatrixXd& B) const {
  const auto& F = g_->fs_;
  if (F.size() == 0) return;
  const auto Se = F.slopes(e);
  std::vector<double> ww;
  F.forms(Se, Se, ww);
  std::vector<Eigen::Matrix<double, 6, 1>> gamma(F.size());
  const Vector3d t = F.t;
  const Matrix3d Tx = skew(t);
  Matrix3d VO = Matrix3d::Zero(), OO = Matrix3d::Zero();
  MatrixXd Oe = MatrixXd::Zero(3, g_->ne_);
  for (std::size_t i = 0; i < F.size(); ++i) {
    const auto& pt = g_->points_[F.point[i]];
    const double m = mass_[F.point[i]], w = 0.5 * ww[i];
    const Vector3d r = pt.p + pt.n.times(e);
    gamma[i] << m * t, m * r.cross(t);
    const Matrix3d Rx = skew(r);
    VO -= m * w * Tx;
    OO -= m * w * (Rx * Tx + Tx * Rx);
    pt.n.add_left(m * w * Tx, Oe);
  }
  A.block<3, 3>(0, 3) += VO;
  A.block<3, 3>(3, 0) += VO.transpose();
  A.block<3, 3>(3, 3) += OO;
  B.bottomRows<3>() += Oe;
  F.apply_rows(gamma, Se, B);
}

// T_fs's equations (Boltzmann–Hamel on V, Ω; Lagrange on e) per point, with S = ṡ + Ω × s and
// K = k̇ + Ω × k (the point's inertial acceleration without the shift):
//   V: m S,   Ω: m (r × S + w t × K),   e: m (Nᵀ S + g t·K + g ẅ),
//   S = t ẅ + (Ω̇ × t) w + 2 ẇ Ω × t + w Ω × (Ω × t),  ẅ = gᵀ ë + χ,  χ = ėᵀ Q ė,
//   K = V̇ + Ω̇ × r + N ë + 2 Ω × N ė + Ω × V + Ω × (Ω × r)
// (g ẅ the axial inertia's: d/dt (m ẇ g) − m ẇ Q ė). The acceleration terms are M_fs's; here the
// rest (S₀, K₀, m g χ): b gains them.
void ScoleNonlinear::Dynamics::add_foreshortening_force(const VectorXd& u, const VectorXd& e, VectorXd& b) const {
  const auto& F = g_->fs_;
  if (F.size() == 0) return;
  const int ne = g_->ne_;
  const Vector3d V = u.head<3>(), W = u.segment<3>(3);
  const VectorXd ed = u.tail(ne);
  std::vector<double> ww, wd, chi, gamma(F.size());
  const auto Se = F.slopes(e), Sd = F.slopes(ed);
  F.forms(Se, Se, ww);
  F.forms(Sd, Se, wd);
  F.forms(Sd, Sd, chi);
  const Vector3d t = F.t, Wt = W.cross(t);
  Vector3d bV = Vector3d::Zero(), bW = Vector3d::Zero();
  VectorXd be = VectorXd::Zero(ne);
  for (std::size_t i = 0; i < F.size(); ++i) {
    const auto& pt = g_->points_[F.point[i]];
    const double m = mass_[F.point[i]], w = 0.5 * ww[i];
    const Vector3d r = pt.p + pt.n.times(e), nd = pt.n.times(ed);
    const Vector3d S0 = m * (t * chi[i] + 2.0 * wd[i] * Wt + w * W.cross(Wt));
    const Vector3d K0 = m * (2.0 * W.cross(nd) + W.cross(V) + W.cross(W.cross(r)));
    bV += S0;
    bW += r.cross(S0) + w * t.cross(K0);
    pt.n.add_transposed(S0, be);
    gamma[i] = t.dot(K0) + m * chi[i];  // + the axial inertia's m g χ
  }
  b.head<3>() += bV;
  b.segment<3>(3) += bW;
  F.apply(gamma, Se, be);
  b.tail(ne) += be;
}

// s_fs = μᵀ R_fs = Σ m σ,  σ = λ·S + κ·K + η (ψ + χ),  λ = μ_V + μ_Ω × r + N μ_e,  κ = η t + w μ_Ω × t,
// η = μ_eᵀ Q e (S, K as above, at the accelerations a). With ψ = a_eᵀ Q e, Ω_t = Ω × t:
//   ∂σ/∂w = λ·(a_Ω × t + Ω × Ω_t) + (μ_Ω × t)·K,  ∂σ/∂ẇ = 2 λ·Ω_t,  ∂σ/∂ψ = ∂σ/∂χ = λ·t + η,
//   ∂σ/∂η = t·K + ψ + χ,
//   ∂σ/∂r = S × μ_Ω + κ × a_Ω + Ω × (Ω × κ),   ∂σ/∂(N ė) = 2 κ × Ω,   ∂σ/∂V = κ × Ω,
//   ∂σ/∂Ω = 2 ẇ t × λ + w (λ (Ω·t) + t (λ·Ω) − 2 (λ·t) Ω) + 2 (N ė) × κ + V × κ
//           + κ (Ω·r) + r (κ·Ω) − 2 (κ·r) Ω;
// ∂/∂e = Nᵀ ∂σ/∂r + ∂σ/∂w Q e + ∂σ/∂ẇ Q ė + ∂σ/∂ψ Q a_e + ∂σ/∂η Q μ_e,
// ∂/∂ė = Nᵀ ∂σ/∂(N ė) + ∂σ/∂ẇ Q e + 2 ∂σ/∂χ Q ė  (each times m; ∂/∂c = weight σ).
void ScoleNonlinear::Dynamics::add_foreshortening_vjp(const VectorXd& u, const VectorXd& e, const VectorXd& a,
                                                      const VectorXd& mu, VectorXd& de, VectorXd& de_dot, VectorXd& du,
                                                      VectorXd* dc) const {
  const auto& F = g_->fs_;
  if (F.size() == 0) return;
  const int ne = g_->ne_;
  const Vector3d V = u.head<3>(), W = u.segment<3>(3);
  const VectorXd ed = u.tail(ne), ae = a.tail(ne), mue = mu.tail(ne);
  const Vector3d aV = a.head<3>(), aW = a.segment<3>(3), muV = mu.head<3>(), muW = mu.segment<3>(3);
  std::vector<double> ww, wd, chi, psi, eta;
  const auto Se = F.slopes(e), Sd = F.slopes(ed), Sa = F.slopes(ae), Sm = F.slopes(mue);
  F.forms(Se, Se, ww);
  F.forms(Sd, Se, wd);
  F.forms(Sd, Sd, chi);
  F.forms(Sa, Se, psi);
  F.forms(Sm, Se, eta);
  const std::size_t n = F.size();
  std::vector<double> g_w(n), g_wd(n), g_t(n), g_t2(n), g_K(n);
  const Vector3d t = F.t, Wt = W.cross(t), muWt = muW.cross(t);
  Vector3d dV = Vector3d::Zero(), dW = Vector3d::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    const auto& pt = g_->points_[F.point[i]];
    const double m = mass_[F.point[i]], w = 0.5 * ww[i], wdot = wd[i];
    const Vector3d r = pt.p + pt.n.times(e), nd = pt.n.times(ed);
    const Vector3d lam = muV + muW.cross(r) + pt.n.times(mue);
    const Vector3d kap = eta[i] * t + w * muWt;
    const Vector3d S = t * (psi[i] + chi[i]) + w * aW.cross(t) + 2.0 * wdot * Wt + w * W.cross(Wt);
    const Vector3d K = aV + aW.cross(r) + pt.n.times(ae) + 2.0 * W.cross(nd) + W.cross(V) + W.cross(W.cross(r));
    const double lt = lam.dot(t), tK = t.dot(K);
    if (dc && pt.coefficient >= 0) (*dc)[pt.coefficient] += pt.weight * (lam.dot(S) + kap.dot(K) + eta[i] * (psi[i] + chi[i]));
    if (m == 0.0) continue;
    g_w[i] = m * (lam.dot(aW.cross(t) + W.cross(Wt)) + muWt.dot(K));
    g_wd[i] = m * 2.0 * lam.dot(Wt);
    g_t[i] = m * (lt + eta[i]);
    g_t2[i] = 2.0 * m * (lt + eta[i]);
    g_K[i] = m * (tK + psi[i] + chi[i]);
    pt.n.add_transposed(m * (S.cross(muW) + kap.cross(aW) + W.cross(W.cross(kap))), de);
    pt.n.add_transposed(2.0 * m * kap.cross(W), de_dot);
    dV += m * kap.cross(W);
    dW += m * (2.0 * wdot * t.cross(lam) + w * (lam * W.dot(t) + t * lam.dot(W) - 2.0 * lt * W) + 2.0 * nd.cross(kap) +
               V.cross(kap) + kap * W.dot(r) + r * kap.dot(W) - 2.0 * kap.dot(r) * W);
  }
  du.head<3>() += dV;
  du.segment<3>(3) += dW;
  F.apply(g_w, Se, de);
  F.apply(g_wd, Sd, de);
  F.apply(g_t, Sa, de);
  F.apply(g_K, Sm, de);
  F.apply(g_wd, Se, de_dot);
  F.apply(g_t2, Sd, de_dot);
}

MatrixXd ScoleNonlinear::Dynamics::mass(const VectorXd& e) const {
  const int ne = g_->ne_;
  Eigen::Matrix<double, 6, 6> A;
  MatrixXd B;
  const auto kin = kinematics(e);
  rigid_rows(e, kin, A, B);
  MatrixXd M = Mconst_;
  M.topLeftCorner<6, 6>() = A;
  M.block(0, 6, 6, ne) = B;
  M.block(6, 0, ne, 6) = B.transpose();
  for (std::size_t i = 0; i < g_->points_.size(); ++i) {
    const auto& cols = g_->points_[i].kin.cols;
    if (cols.empty()) continue;
    const MatrixXd Mi = mass_[i] * kin[i].J.transpose() * kin[i].J;
    for (std::size_t a = 0; a < cols.size(); ++a)
      for (std::size_t b = 0; b < cols.size(); ++b)
        M(6 + cols[a], 6 + cols[b]) += Mi(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(b));
  }
  for_turned_rotors(e, [&](int a, int b, double v) { M(6 + a, 6 + b) += v; });
  // The mast's axial inertia Σ m g gᵀ, g = Q e (column by column: ΔM e_k).
  const auto& F = g_->fs_;
  if (F.size() > 0) {
    const auto Se = F.slopes(e);
    std::vector<double> gk;
    for (int k = 0; k < ne; ++k) {
      F.forms(Se, F.slopes(VectorXd(VectorXd::Unit(ne, k))), gk);
      for (std::size_t i = 0; i < F.size(); ++i) gk[i] *= mass_[F.point[i]];
      VectorXd col = VectorXd::Zero(ne);
      F.apply(gk, Se, col);
      M.block(6, 6 + k, ne, 1) += col;
    }
  }
  return M;
}

// Θ(e)ᵀ J(θ) Θ(e) − Θᵀ J Θ on a turned rotor's columns: the e-dependent part of its e–e block.
MatrixXd ScoleNonlinear::Dynamics::rotor_block(std::size_t j, const VectorXd& e) const {
  const auto& rt = g_->rotors_[j];
  const Matrix3d& J = J_[j];
  const auto Te = rt.jacobian(e);
  return Te.transpose() * (J + rotor_scale_[j] * rt.turn.change(rt.th.times(e))) * Te - rt.th.v.transpose() * J * rt.th.v;
}

// rotor_block on each turned rotor's columns (the e–e part of its turned inertia).
template <class Add>
void ScoleNonlinear::Dynamics::for_turned_rotors(const VectorXd& e, Add&& add) const {
  for (std::size_t j = 0; j < g_->rotors_.size(); ++j) {
    const auto& th = g_->rotors_[j].th;
    if (th.cols.empty()) continue;
    const MatrixXd Mj = rotor_block(j, e);
    for (std::size_t a = 0; a < th.cols.size(); ++a)
      for (std::size_t b = 0; b < th.cols.size(); ++b)
        add(th.cols[a], th.cols[b], Mj(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(b)));
  }
}

// M x = r by the Schur complement on the rigid rows: M = [A B; Bᵀ C] with C = M_ee (sparse: the
// elements' band and the proof masses; factorised once per coefficient set when constant, per e
// with nonlinear points):
// S = A − B C⁻¹ Bᵀ (6 × 6), x_r = S⁻¹ (r_r − B C⁻¹ r_e), x_e = C⁻¹ (r_e − Bᵀ x_r).
VectorXd ScoleNonlinear::Dynamics::solve_mass(const VectorXd& e, const VectorXd& r) const {
  return solve_mass(e, r, kinematics(e));
}

VectorXd ScoleNonlinear::Dynamics::solve_mass(const VectorXd& e, const VectorXd& r,
                                              const std::vector<Kinematics::At>& kin) const {
  const int ne = g_->ne_;
  Eigen::Matrix<double, 6, 6> A;
  MatrixXd B;
  rigid_rows(e, kin, A, B);
  if (e_dependent_) {
    // M_ee(e) = the constant part + Σ m J_lᵀ J_l (J_l = N(e) − t (Q ê)ᵀ, on the point's local
    // columns: sparse) + for an axial part the rank-2 m [(v + g)(v + g)ᵀ − v vᵀ], g = Q ê,
    // v = J_lᵀ t, which the Woodbury identity takes.
    SparseMatrix C = Cbase_;
    double* values = C.valuePtr();
    for (std::size_t j = 0; j < g_->rotors_.size(); ++j) {
      const auto& th = g_->rotors_[j].th;
      if (th.cols.empty()) continue;
      const MatrixXd Mj = rotor_block(j, e);
      const auto& sl = rotor_slots_[j];
      const auto n = static_cast<Eigen::Index>(th.cols.size());
      for (Eigen::Index a = 0; a < n; ++a)
        for (Eigen::Index b = 0; b < n; ++b) values[sl[static_cast<std::size_t>(a * n + b)]] += Mj(a, b);
    }
    // Points with the same axial part (the reflector's: one Q, one g) share one rank-2 term,
    //   Σ m_i [(v_i + g)(v_i + g)ᵀ − v_i v_iᵀ] = V gᵀ + g Vᵀ + m g gᵀ = [V g] [0 1; 1 m] [V g]ᵀ,
    // V = Σ m_i v_i, m = Σ m_i (the middle matrix has determinant −1 whatever m).
    struct Axial {
      const std::vector<int>* cols;
      VectorXd g, V;
      double m = 0.0;
    };
    std::vector<Axial> axial;
    for (std::size_t i = 0; i < g_->points_.size(); ++i) {
      const auto& q = g_->points_[i].kin;
      if (!q.active() || mass_[i] == 0.0) continue;
      Eigen::Matrix<double, 3, Eigen::Dynamic> Jl = kin[i].J;
      VectorXd gq;
      if (q.axial()) {
        gq = kin[i].Qg;
        Jl -= q.t * gq.transpose();
      }
      // m J_lᵀ J_l on the local columns only (J_l vanishes on the others).
      const auto& loc = q.local_index;
      const auto nl = static_cast<Eigen::Index>(loc.size());
      Eigen::Matrix<double, 3, Eigen::Dynamic> Jloc(3, nl);
      for (Eigen::Index a = 0; a < nl; ++a) Jloc.col(a) = Jl.col(loc[static_cast<std::size_t>(a)]);
      const MatrixXd Mi = mass_[i] * Jloc.transpose() * Jloc;
      const auto& sl = point_slots_[i];
      const auto n = static_cast<Eigen::Index>(q.cols.size());
      for (Eigen::Index a = 0; a < nl; ++a)
        for (Eigen::Index b = 0; b < nl; ++b)
          values[sl[static_cast<std::size_t>(loc[static_cast<std::size_t>(a)] * n + loc[static_cast<std::size_t>(b)])]] +=
              Mi(a, b);
      if (q.axial()) {
        const VectorXd v = Jl.transpose() * q.t;
        Axial* grp = nullptr;
        for (auto& x : axial)
          if (*x.cols == q.cols && x.g == gq) grp = &x;
        if (!grp) {
          axial.push_back({&q.cols, gq, VectorXd::Zero(gq.size()), 0.0});
          grp = &axial.back();
        }
        grp->V += mass_[i] * v;
        grp->m += mass_[i];
      }
    }
    MatrixXd U = MatrixXd::Zero(ne, static_cast<Eigen::Index>(2 * axial.size()));
    MatrixXd Cinv = MatrixXd::Zero(U.cols(), U.cols());  // blocks [0 1; 1 m]⁻¹ = [−m 1; 1 0]
    for (std::size_t x = 0; x < axial.size(); ++x) {
      const auto c0 = static_cast<Eigen::Index>(2 * x);
      const auto& cols = *axial[x].cols;
      for (std::size_t k = 0; k < cols.size(); ++k) {
        U(cols[k], c0) = axial[x].V[static_cast<Eigen::Index>(k)];
        U(cols[k], c0 + 1) = axial[x].g[static_cast<Eigen::Index>(k)];
      }
      Cinv(c0, c0) = -axial[x].m;
      Cinv(c0, c0 + 1) = Cinv(c0 + 1, c0) = 1.0;
    }
    // The DOFs are numbered along the mast (banded): no reordering.
    Eigen::SimplicialLLT<SparseMatrix, Eigen::Lower, Eigen::NaturalOrdering<int>> factor(C);
    if (factor.info() != Eigen::Success)
      throw std::runtime_error("ScoleNonlinear: the elastic mass block is not positive definite at this deformation");
    if (U.cols() == 0)
      return axial_inertia_solve(e, r, schur_solver(A, B, [&](const MatrixXd& X) { return MatrixXd(factor.solve(X)); }));
    const MatrixXd Z = factor.solve(U);
    const MatrixXd cap = Cinv + U.transpose() * Z;
    const Eigen::PartialPivLU<MatrixXd> capf(cap);
    return axial_inertia_solve(e, r, schur_solver(A, B, [&](const MatrixXd& X) {
                                 const MatrixXd Y0 = factor.solve(X);
                                 return MatrixXd(Y0 - Z * capf.solve(MatrixXd(U.transpose() * Y0)));
                               }));
  }
  return axial_inertia_solve(e, r, schur_solver(A, B, [&](const MatrixXd& X) { return MatrixXd(C_->solve(X)); }));
}

// M₀ with M₀ = [A B; Bᵀ C] by its Schur complement: C⁻¹ Bᵀ and S = A − B C⁻¹ Bᵀ once, then one
// C-solve per right-hand side: x_r = S⁻¹ (r_r − B C⁻¹ r_e), x_e = C⁻¹ r_e − C⁻¹ Bᵀ x_r.
template <class SolveC>
std::function<VectorXd(const VectorXd&)> ScoleNonlinear::Dynamics::schur_solver(const Eigen::Matrix<double, 6, 6>& A,
                                                                                 const MatrixXd& B,
                                                                                 const SolveC& solve_C) const {
  const int ne = g_->ne_;
  const MatrixXd Y = solve_C(MatrixXd(B.transpose()));  // C⁻¹ Bᵀ
  const Eigen::Matrix<double, 6, 6> S = A - B * Y;
  const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> Sf(S);
  return [=](const VectorXd& r) {
    const VectorXd Cre = solve_C(MatrixXd(r.tail(ne))).col(0);
    const Eigen::Matrix<double, 6, 1> xr = Sf.solve(Eigen::Matrix<double, 6, 1>(r.head<6>() - B * Cre));
    VectorXd x(6 + ne);
    x.head<6>() = xr;
    x.tail(ne) = Cre - Y * xr;
    return x;
  };
}

// M x = r with M = M₀ + ΔM, ΔM = Σ_i m_i g_i g_iᵀ on the e block (g_i = Q_i e: the axial inertia
// ½ m ẇ² of the mast's foreshortening, dense, growing as |u'|²). Conjugate gradients on M
// preconditioned by M₀ (both symmetric positive definite): M₀ p is carried along by the recursion
// (p_k = z_k + β p_{k−1}, z_k = M₀⁻¹ r_k ⇒ M₀ p_k = r_k + β M₀ p_{k−1}), so only M₀⁻¹ and ΔM
// (O(ne) by struct Foreshortening) are applied. M₀⁻¹ M has its spectrum in [1, 1 + ρ],
// ρ = max xᵀ ΔM x / xᵀ M₀ x, and CG gains about a factor ρ/4 per iteration while ρ is small.
VectorXd ScoleNonlinear::Dynamics::axial_inertia_solve(const VectorXd& e, const VectorXd& r,
                                                       const std::function<VectorXd(const VectorXd&)>& solve0) const {
  const auto& F = g_->fs_;
  VectorXd x = solve0(r);
  if (F.size() == 0) return x;
  const int ne = g_->ne_;
  const auto Se = F.slopes(e);
  std::vector<double> gx;
  auto dM = [&](const VectorXd& v) {  // ΔM v
    F.forms(Se, F.slopes(VectorXd(v.tail(ne))), gx);
    for (std::size_t i = 0; i < F.size(); ++i) gx[i] *= mass_[F.point[i]];
    VectorXd out = VectorXd::Zero(6 + ne);
    VectorXd oe = VectorXd::Zero(ne);
    F.apply(gx, Se, oe);
    out.tail(ne) = oe;
    return out;
  };
  // First step from x = M₀⁻¹ r (p = x, M₀ p = r).
  VectorXd p = x, M0p = r;
  const VectorXd dMp = dM(p);
  if (dMp.isZero(0.0)) return x;  // at e = 0
  double rz = r.dot(x);
  const double rz0 = rz;
  if (!std::isfinite(rz0)) return x;  // a non-finite right-hand side: the caller sees it in x
  VectorXd Mp = M0p + dMp;
  double pMp = p.dot(Mp);
  if (!(pMp > 0.0)) throw std::runtime_error("ScoleNonlinear: the mass matrix is not positive definite at this deformation");
  double alpha = rz / pMp;
  x *= alpha;
  VectorXd res = r - alpha * Mp;
  constexpr double kTol = 1e-26;  // (M₀⁻¹-norm of the residual / of r)²
  for (int k = 0; k < 100; ++k) {
    const VectorXd z = solve0(res);
    const double rz_new = res.dot(z);
    if (rz_new <= kTol * rz0) return x;
    const double beta = rz_new / rz;
    rz = rz_new;
    M0p = res + beta * M0p;
    p = z + beta * p;
    Mp = M0p + dM(p);
    pMp = p.dot(Mp);
    if (!(pMp > 0.0)) throw std::runtime_error("ScoleNonlinear: the mass matrix is not positive definite at this deformation");
    alpha = rz / pMp;
    x += alpha * p;
    res -= alpha * Mp;
  }
  throw std::runtime_error("ScoleNonlinear: the mass solve with the mast's axial inertia did not converge at this deformation");
}

VectorXd ScoleNonlinear::Dynamics::internal(const VectorXd& u, const VectorXd& e) const {
  return internal(u, e, kinematics(e));
}

VectorXd ScoleNonlinear::Dynamics::internal(const VectorXd& u, const VectorXd& e,
                                            const std::vector<Kinematics::At>& kin) const {
  const int ne = g_->ne_;
  const Vector3d V = u.head<3>(), W = u.segment<3>(3);
  const VectorXd ed = u.tail(ne);
  VectorXd b = VectorXd::Zero(6 + ne);
  for (std::size_t i = 0; i < g_->points_.size(); ++i) {
    const auto& p = g_->points_[i];
    const double mi = mass_[i];
    if (mi == 0.0) continue;
    if (p.kin.active()) {
      const auto& q = p.kin;
      const auto& k = kin[i];
      const auto& Je = k.J;
      const Vector3d r = p.p + p.n.times(e) + k.offset, w = Je * q.gather(ed);
      const Vector3d f = mi * (W.cross(V) + W.cross(W.cross(r)) + 2.0 * W.cross(w) + k.convective(ed));
      b.head<3>() += f;
      b.segment<3>(3) += r.cross(f);
      const VectorXd g = Je.transpose() * f;
      for (std::size_t k = 0; k < q.cols.size(); ++k) b[6 + q.cols[k]] += g[static_cast<Eigen::Index>(k)];
      continue;
    }
    const Vector3d r = p.p + p.n.times(e), w = p.n.times(ed);
    const Vector3d f = mi * (W.cross(V) + W.cross(W.cross(r)) + 2.0 * W.cross(w));
    b.head<3>() += f;
    b.segment<3>(3) += r.cross(f);
    VectorXd be = b.tail(ne);
    p.n.add_transposed(f, be);
    b.tail(ne) = be;
  }
  for (std::size_t j = 0; j < g_->rotors_.size(); ++j) {
    // ω = Ω + Θ(e) ė, h = J(θ) ω, ḣ = J(θ) ω̇ + J̇ ω with ω̇ = Ω̇ + Θ(e) ë + ṗ × q̇ (ṗ = P⊥ Θ ė,
    // q̇ = B ė) and J̇ ω = ∂J/∂θ[θ̇] ω. Ω row: the convective part of ḣ, plus Ω × h;
    // e row (Lagrange, T = ½ ωᵀ J(θ) ω): Θ(e)ᵀ (convective ḣ) + Bᵀ (h × ṗ) − Aᵀ (q̇ × h)
    // − Θᵀ ∂T/∂θ, A = P⊥ Θ: the first two from d/dt of Θ(e)ᵀ, the third ∂ω/∂e, the last ∂J/∂θ.
    const auto& rt = g_->rotors_[j];
    const auto& th = rt.th;
    const Matrix3d& J = J_[j];
    if (th.cols.empty()) {
      b.segment<3>(3) += W.cross(J * W);
      continue;
    }
    const VectorXd edl = gather_cols(th.cols, ed);
    const Vector3d thd = th.v * edl, pd = Vector3d(thd[0], thd[1], 0.0), qd = rt.half * edl;
    const Vector3d omega = W + thd + rt.tilt(e).cross(qd);
    const Vector3d theta = th.times(e);
    const double sc = rotor_scale_[j];
    const Matrix3d Jt = J + sc * rt.turn.change(theta);
    const auto Jk = rt.turn.slopes(theta);  // ∂J/∂θ_k / sc
    const Vector3d h = Jt * omega;
    // J̇ ω = Σ_k θ̇_k ∂J/∂θ_k ω; ∂T/∂θ_k = ½ ω · ∂J/∂θ_k ω.
    Vector3d Jdw = Vector3d::Zero(), dT;
    for (std::size_t k = 0; k < 3; ++k) {
      const Vector3d Jkw = Jk[k] * omega;
      Jdw += thd[static_cast<Eigen::Index>(k)] * Jkw;
      dT[static_cast<Eigen::Index>(k)] = 0.5 * sc * omega.dot(Jkw);
    }
    const Vector3d conv = Jt * pd.cross(qd) + sc * Jdw;
    b.segment<3>(3) += conv + W.cross(h);
    const VectorXd g = rt.jacobian(e).transpose() * conv + rt.half.transpose() * h.cross(pd) -
                       th.v.transpose() * (tilt_of(qd.cross(h)) + dT);
    for (std::size_t k = 0; k < th.cols.size(); ++k) b[6 + th.cols[k]] += g[static_cast<Eigen::Index>(k)];
  }
  add_foreshortening_force(u, e, b);
  b.tail(ne).noalias() += D_ * ed + K_ * e;
  VectorXd be = b.tail(ne);
  add_coupling_force(e, be);
  b.tail(ne) = be;
  return b;
}

VectorXd ScoleNonlinear::Dynamics::load(const VectorXd& f, const VectorXd& e) const {
  VectorXd Q = VectorXd::Zero(g_->speeds());
  for (std::size_t i = 0; i < g_->inputs_.size(); ++i) {
    const auto& in = g_->inputs_[i];
    const double fi = f[static_cast<Eigen::Index>(i)];
    if (fi == 0.0) continue;
    // An input with a coefficient is scaled by it (γ_i, structural_model.h); the loads are not
    // part of the residual's coefficient derivative, so `constants` does not touch them.
    const double gi = fi * input_scale_[i];
    Q += gi * in.q0;
    if (in.arm) Q.segment<3>(3) += gi * Vector3d(in.N * e).cross(in.d);
    if (in.kin) {
      const auto k = in.kin->at(e, nullptr, false);
      Q.segment<3>(3) += gi * k.offset.cross(in.d);
      VectorXd Qe = Q.tail(g_->ne_);
      k.rows_t(gi * in.d, Qe);  // (N(e) − N)ᵀ d f
      Q.tail(g_->ne_) = Qe;
    }
  }
  return Q;
}

void ScoleNonlinear::Dynamics::derivative(const double* y, const VectorXd& f, double* ydot, VectorXd* udot) const {
  const int ne = g_->ne_;
  const StateView s(y, ne);
  Eigen::Map<Vector3d> Xdot(ydot), phidot(ydot + 3);
  Eigen::Map<VectorXd> edot(ydot + 6, ne), accel(ydot + 6 + ne, 6 + ne);
  Xdot = rotation_matrix(s.phi) * s.V;
  phidot = right_jacobian_inverse(s.phi) * s.Omega;
  edot = s.edot;
  const VectorXd e = s.e, u = s.u;
  const auto kin = kinematics(e);
  const VectorXd a = solve_mass(e, load(f, e) - internal(u, e, kin), kin);
  accel = a;
  if (udot) *udot = a;
}

VectorXd ScoleNonlinear::Dynamics::residual(const double* y, const VectorXd& udot, const VectorXd& f) const {
  const StateView s(y, g_->ne_);
  const VectorXd e = s.e, u = s.u;
  return mass(e) * udot + internal(u, e) - load(f, e);
}

VectorXd ScoleNonlinear::Dynamics::outputs(const double* y, const VectorXd& udot) const {
  const int ne = g_->ne_;
  const StateView s(y, ne);
  const Vector3d Vd = udot.head<3>(), Wd = udot.segment<3>(3);
  const VectorXd edd = udot.tail(ne);
  VectorXd z(g_->sensors());
  using K = Sensor::Kind;
  for (int k = 0; k < g_->sensors(); ++k) {
    const auto& se = g_->sensors_[static_cast<std::size_t>(k)];
    double v = 0.0;
    switch (se.kind) {
      case K::ShuttleRotation: v = s.phi.dot(se.d); break;
      case K::ShuttleDisplacement: v = s.X.dot(se.d); break;
      case K::ShuttleVelocity: v = (rotation_matrix(s.phi) * s.V).dot(se.d); break;
      case K::ShuttleAcceleration: v = (rotation_matrix(s.phi) * (Vd + s.Omega.cross(s.V))).dot(se.d); break;
      case K::Row: v = se.row.dot(s.e); break;
      case K::RateRow: v = se.row.dot(s.edot); break;
      case K::PointAcceleration: {
        Vector3d r = se.p + se.N * s.e, n = se.N * s.edot, ne2 = se.N * edd;
        Vector3d conv = Vector3d::Zero();
        if (se.kin) {  // r(e), N(e) ė, N(e) ë and the convective r''[ė, ė] (§3.8)
          const VectorXd ed = s.edot;
          const auto k = se.kin->at(s.e, nullptr, false);
          r += k.offset;
          n += k.rows(ed);
          ne2 += k.rows(edd);
          conv = k.convective(ed);
        }
        const Vector3d a =
            Vd + Wd.cross(r) + ne2 + conv + s.Omega.cross(s.V) + s.Omega.cross(s.Omega.cross(r)) + 2.0 * s.Omega.cross(n);
        v = a.dot(se.d);
        break;
      }
    }
    z[k] = v;
  }
  return z;
}

double ScoleNonlinear::Dynamics::energy(const double* y) const {
  const StateView s(y, g_->ne_);
  const VectorXd e = s.e, u = s.u;
  return 0.5 * u.dot(mass(e) * u) + 0.5 * e.dot(K_ * e) + coupling_energy(e);
}

Vector3d ScoleNonlinear::Dynamics::momentum(const double* y) const {
  const StateView s(y, g_->ne_);
  const VectorXd e = s.e, u = s.u;
  const VectorXd h = mass(e) * u;
  return rotation_matrix(s.phi) * h.head<3>();
}

Vector3d ScoleNonlinear::Dynamics::angular_momentum(const double* y) const {
  const StateView s(y, g_->ne_);
  const VectorXd e = s.e, u = s.u;
  const VectorXd h = mass(e) * u;
  const Matrix3d R = rotation_matrix(s.phi);
  const Vector3d X = s.X;
  return X.cross(R * h.head<3>()) + R * h.segment<3>(3);
}

}  // namespace scoleid::identify

namespace scoleid::identify {

// s = μᵀ (M(e) a + b(u, e) + D ė + K e − Q(t, e)), term by term (docs/theory.md §6.7). Per mass
// point, with w = L μ = μ_V + μ_Ω × r + N μ_e and the point's force f = m (L a + γ), s_i = wᵀ f:
//   ∂s_i/∂r = f × μ_Ω + m (w × a_Ω + Ω × (Ω × w))                      (∂/∂e = Nᵀ ∂/∂r)
//   ∂s_i/∂V = m w × Ω,   ∂s_i/∂ė = 2 m Nᵀ (w × Ω),
//   ∂s_i/∂Ω = m (V × w + w (Ω·r) + r (w·Ω) − 2 (w·r) Ω + 2 (N ė) × w).
// Per rotor: below, at its loop (the inertia turned by θ adds θ- and θ̇-terms). A nonlinear point
// (struct Kinematics): N(e) for N and the e-derivatives of N(e), at its branch.
// Elastic: ∂/∂ė = D μ_e, ∂/∂e = K μ_e. A force's arm: ∂/∂e of −f μ_Ω · ((N e) × d) = −f Nᵀ (d × μ_Ω).
// The state, accelerations and multiplier of residual_vjp split into their rigid and elastic parts.
struct ScoleNonlinear::Dynamics::VjpFrame {
  VjpFrame(const StateView& s, const VectorXd& a, const VectorXd& mu)
      : V(s.V), W(s.Omega), aV(a.head<3>()), aW(a.segment<3>(3)), ae(a.tail(s.e.size())), muV(mu.head<3>()),
        muW(mu.segment<3>(3)), mue(mu.tail(s.e.size())), e(s.e), edot(s.edot) {}
  Vector3d V, W, aV, aW;
  VectorXd ae;
  Vector3d muV, muW;
  VectorXd mue, e, edot;
};

void ScoleNonlinear::Dynamics::residual_vjp(const double* y, const VectorXd& a, const VectorXd& mu,
                                            const VectorXd& fin, VectorXd& de, VectorXd& du, VectorXd* dc,
                                            const std::vector<Kinematics::At>& kin) const {
  const int ne = g_->ne_;
  const StateView s(y, ne);
  const VjpFrame fr(s, a, mu);
  const VectorXd& mue = fr.mue;
  de = VectorXd::Zero(ne);
  du = VectorXd::Zero(6 + ne);
  VectorXd due = VectorXd::Zero(ne);  // ∂s/∂ė, gathered apart and added to du at the end
  if (dc) *dc = VectorXd::Zero(g_->ncoef_);
  add_points_vjp(fr, kin, de, du, due, dc);
  add_rotors_vjp(fr, de, du, due, dc);
  de.noalias() += K_ * mue;
  add_coupling_hessian(fr.e, mue, de);
  add_foreshortening_vjp(s.u, fr.e, a, mu, de, due, du, dc);
  due.noalias() += D_ * mue;
  du.tail(ne) += due;
  if (dc) {
    add_coupling_coefficients(fr.e, mue, *dc);
    for (const auto& t : g_->stiffness_)
      if (t.coefficient >= 0) (*dc)[t.coefficient] += mue.dot(t.matrix * fr.e);
    for (const auto& t : g_->damping_)
      if (t.coefficient >= 0) (*dc)[t.coefficient] += mue.dot(t.matrix * fr.edot);
  }
  add_inputs_vjp(fr, fin, mu, de, dc);
}

// The mass points' part of residual_vjp (ds/de into de, ds/dė into due, ds/dV and ds/dΩ into du).
void ScoleNonlinear::Dynamics::add_points_vjp(const VjpFrame& fr, const std::vector<Kinematics::At>& kin, VectorXd& de,
                                              VectorXd& du, VectorXd& due, VectorXd* dc) const {
  const Vector3d V = fr.V, W = fr.W;
  const Vector3d aV = fr.aV, aW = fr.aW;
  const VectorXd& ae = fr.ae;
  const Vector3d muV = fr.muV, muW = fr.muW;
  const VectorXd& mue = fr.mue;
  const VectorXd &e = fr.e, &edot = fr.edot;
  std::vector<VectorXd> axial_e(g_->axial_rep_.size()), axial_edot(g_->axial_rep_.size());
  for (std::size_t i = 0; i < g_->points_.size(); ++i) {
    const auto& p = g_->points_[i];
    const double m = mass_[i];
    if (m == 0.0 && !(dc && p.coefficient >= 0)) continue;
    if (p.kin.active()) {
      // As below with N(e) for N, plus the e-dependence of N(e) (second_t) and the γ term r''[ė, ė]
      // (its ė-derivative by second_t, its e-derivative at fixed ė by convective_t).
      const auto& q = p.kin;
      const auto& k = kin[i];
      const auto& Je = k.J;
      const Vector3d r = p.p + p.n.times(e) + k.offset, n = Je * q.gather(edot);
      const Vector3d w = muV + muW.cross(r) + Je * q.gather(mue);
      const Vector3d acc = aV + aW.cross(r) + Je * q.gather(ae) + W.cross(V) + W.cross(W.cross(r)) + 2.0 * W.cross(n) +
                           k.convective(edot);
      if (dc && p.coefficient >= 0) (*dc)[p.coefficient] += p.weight * w.dot(acc);
      if (m == 0.0) continue;
      const Vector3d f = m * acc;
      const Vector3d ds_dr = f.cross(muW) + m * (w.cross(aW) + W.cross(W.cross(w)));
      const VectorXd gr = Je.transpose() * ds_dr, ge = Je.transpose() * Vector3d(2.0 * m * w.cross(W));
      for (std::size_t k = 0; k < q.cols.size(); ++k) {
        de[q.cols[k]] += gr[static_cast<Eigen::Index>(k)];
        due[q.cols[k]] += ge[static_cast<Eigen::Index>(k)];
      }
      VectorXd *ax = nullptr, *ax_dot = nullptr;  // the axial part's Q products, once per group
      if (q.axial()) {
        const auto g = static_cast<std::size_t>(q.axial_group);
        if (axial_e[g].size() == 0) axial_e[g] = axial_edot[g] = VectorXd::Zero(static_cast<Eigen::Index>(q.cols.size()));
        ax = &axial_e[g];
        ax_dot = &axial_edot[g];
      }
      k.second_t(mue, f, de, ax);
      k.second_t(ae, m * w, de, ax);
      k.second_t(edot, 2.0 * m * w.cross(W), de, ax);
      k.convective_t(edot, m * w, de);
      k.second_t(edot, 2.0 * m * w, due, ax_dot);
      du.head<3>() += m * w.cross(W);
      du.segment<3>(3) += m * (V.cross(w) + w * W.dot(r) + r * w.dot(W) - 2.0 * w.dot(r) * W + 2.0 * n.cross(w));
      continue;
    }
    const Vector3d r = p.p + p.n.times(e), n = p.n.times(edot);
    const Vector3d w = muV + muW.cross(r) + p.n.times(mue);
    const Vector3d acc = aV + aW.cross(r) + p.n.times(ae) + W.cross(V) + W.cross(W.cross(r)) + 2.0 * W.cross(n);
    if (dc && p.coefficient >= 0) (*dc)[p.coefficient] += p.weight * w.dot(acc);
    if (m == 0.0) continue;
    const Vector3d f = m * acc;
    const Vector3d ds_dr = f.cross(muW) + m * (w.cross(aW) + W.cross(W.cross(w)));
    p.n.add_transposed(ds_dr, de);
    du.head<3>() += m * w.cross(W);
    du.segment<3>(3) += m * (V.cross(w) + w * W.dot(r) + r * w.dot(W) - 2.0 * w.dot(r) * W + 2.0 * n.cross(w));
    p.n.add_transposed(2.0 * m * w.cross(W), due);
  }
  for (std::size_t g = 0; g < axial_e.size(); ++g)
    if (axial_e[g].size() != 0) {
      const auto& q = g_->points_[g_->axial_rep_[g]].kin;
      q.add_axial(axial_e[g], de);
      q.add_axial(axial_edot[g], due);
    }
}

  // Per rotor (struct Rotor), with θ = Θ e, θ̇ = Θ ė, p = P⊥ θ, ṗ = P⊥ θ̇, q̇ = B ė,
  // ω = Ω + θ̇ + p × q̇, J(θ) = J + ΔJ(θ) (symmetric, second order: struct Turning), h = J(θ) ω, and from μ: z = Θ μ_e,
  // m_A = P⊥ z, m_B = B μ_e, ν = μ_Ω + z + p × m_B (= L(e) μ); α = a_Ω + Θ a_e + p × B a_e,
  // c = ṗ × q̇, x = μ_Ω × Ω + ṗ × m_B − m_A × q̇:
  //   s_j = ν·J(θ)(α + c) + θ̇·G(ν, ω) + x·J(θ) ω − ½ z·G(ω, ω),
  // G(a, b) = ∇_θ (a·J(θ) b) (so θ̇·G(ν, ω) = ν·J̇ ω and ½ G(ω, ω) = ∂T/∂θ), J'[d] = ∂J/∂θ along
  // d, and C_u(a, b) = ∇_θ (u·G(a, b)) (J(θ) is quadratic in θ: C does not depend on θ). With
  // g_ν, g_ω, … the partial gradients:
  //   g_θ = G(ν, α + c) + G(x, ω) + C_θ̇(ν, ω) − ½ C_z(ω, ω),   g_θ̇ = G(ν, ω),
  //   g_ω = J'[θ̇] ν + J(θ) x − J'[z] ω,
  //   g_ν = J(θ)(α + c) + J'[θ̇] ω,   g_ṗ = m_B × h + q̇ × J(θ) ν,
  //   g_q̇ = m_A × h + J(θ) ν × ṗ + g_ω × p,     g_p = m_B × g_ν + B a_e × J(θ) ν + q̇ × g_ω;
  //   ∂/∂e = Θᵀ (g_θ + P⊥ g_p),  ∂/∂ė = Θᵀ (g_θ̇ + g_ω + P⊥ g_ṗ) + Bᵀ g_q̇,  ∂/∂Ω = h × μ_Ω + g_ω.
void ScoleNonlinear::Dynamics::add_rotors_vjp(const VjpFrame& fr, VectorXd& de, VectorXd& du, VectorXd& due,
                                              VectorXd* dc) const {
  const Vector3d W = fr.W, aW = fr.aW, muW = fr.muW;
  const VectorXd &ae = fr.ae, &mue = fr.mue, &e = fr.e, &edot = fr.edot;
  for (std::size_t j = 0; j < g_->rotors_.size(); ++j) {
    const auto& rt = g_->rotors_[j];
    const Vector3d yv = muW.cross(W);
    if (rt.th.cols.empty()) {  // the shuttle: s = μ_Ω·(J a_Ω + Ω × J Ω)
      if (dc && rt.coefficient >= 0) (*dc)[rt.coefficient] += muW.dot(rt.J * aW + W.cross(rt.J * W));
      const Matrix3d& J = J_[j];
      du.segment<3>(3) += Vector3d(J * W).cross(muW) + J * yv;
      continue;
    }
    const VectorXd el = gather_cols(rt.th.cols, e), edl = gather_cols(rt.th.cols, edot), mul = gather_cols(rt.th.cols, mue),
                   ael = gather_cols(rt.th.cols, ae);
    const Vector3d th = rt.th.v * el, thd = rt.th.v * edl, p = tilt_of(th), pd = tilt_of(thd), qd = rt.half * edl;
    const Vector3d omega = W + thd + p.cross(qd);
    const Vector3d z = rt.th.v * mul, mA = tilt_of(z), mB = rt.half * mul, nu = muW + z + p.cross(mB);
    const Vector3d Ba = rt.half * ael, alpha = aW + rt.th.v * ael + p.cross(Ba), ac = alpha + pd.cross(qd);
    const Vector3d x = yv + pd.cross(mB) - mA.cross(qd);
    // Everything below is linear in J: with Ĵ(θ) = Rotor::J turned (unscaled) the value is s_j / scale.
    const auto Jk = rt.turn.slopes(th);  // ∂Ĵ/∂θ_k
    Matrix3d Jd = Matrix3d::Zero(), Jz = Matrix3d::Zero();  // ∂Ĵ/∂θ along θ̇ and along z
    Vector3d G_nu_ac, G_x_w, G_nu_w, G_w_w;                // ∇_θ (a · Ĵ(θ) b)
    for (std::size_t k = 0; k < 3; ++k) {
      const auto kk = static_cast<Eigen::Index>(k);
      Jd += thd[kk] * Jk[k];
      Jz += z[kk] * Jk[k];
      const Vector3d Jkw = Jk[k] * omega, Jknu = Jk[k] * nu;
      G_nu_ac[kk] = Jknu.dot(ac);
      G_x_w[kk] = x.dot(Jkw);
      G_nu_w[kk] = Jknu.dot(omega);
      G_w_w[kk] = omega.dot(Jkw);
    }
    const Matrix3d Jhat = rt.J + rt.turn.change(th);
    if (dc && rt.coefficient >= 0)
      (*dc)[rt.coefficient] += nu.dot(Jhat * ac) + nu.dot(Jd * omega) + x.dot(Jhat * omega) - 0.5 * z.dot(G_w_w);
    const double sc = rotor_scale_[j];
    const Matrix3d Jt = sc * Jhat;
    const Vector3d Jtnu = Jt * nu, h = Jt * omega;
    const Vector3d g_th = sc * (G_nu_ac + G_x_w + rt.turn.curvature(thd, nu, omega) - 0.5 * rt.turn.curvature(z, omega, omega));
    const Vector3d g_thd = sc * G_nu_w;
    const Vector3d g_w = sc * (Jd * nu - Jz * omega) + Jt * x;
    const Vector3d g_nu = Jt * ac + sc * (Jd * omega);
    const Vector3d g_pd = mB.cross(h) + qd.cross(Jtnu);
    const Vector3d g_qd = mA.cross(h) + Jtnu.cross(pd) + g_w.cross(p);
    const Vector3d g_p = mB.cross(g_nu) + Ba.cross(Jtnu) + qd.cross(g_w);
    du.segment<3>(3) += h.cross(muW) + g_w;
    const VectorXd ge = rt.th.v.transpose() * Vector3d(g_th + tilt_of(g_p));
    const VectorXd gd = rt.th.v.transpose() * Vector3d(g_thd + g_w + tilt_of(g_pd)) + rt.half.transpose() * g_qd;
    for (std::size_t k = 0; k < rt.th.cols.size(); ++k) {
      de[rt.th.cols[k]] += ge[static_cast<Eigen::Index>(k)];
      due[rt.th.cols[k]] += gd[static_cast<Eigen::Index>(k)];
    }
  }
}

// The loads' part of residual_vjp: a force's arm and, at a nonlinear point, its own kinematics.
void ScoleNonlinear::Dynamics::add_inputs_vjp(const VjpFrame& fr, const VectorXd& fin, const VectorXd& mu, VectorXd& de,
                                              VectorXd* dc) const {
  const Vector3d muW = fr.muW;
  const VectorXd &mue = fr.mue, &e = fr.e;
  for (std::size_t i = 0; i < g_->inputs_.size(); ++i) {
    const auto& in = g_->inputs_[i];
    const double fi = fin[static_cast<Eigen::Index>(i)];
    if (fi == 0.0) continue;
    const double gi = fi * input_scale_[i];
    if (in.arm) de.noalias() -= gi * (in.N.transpose() * in.d.cross(muW));
    if (in.kin) {
      // −f [μ_Ω · (offset(e) × d) + d · (N(e) − N) μ_e]:  ∂/∂e = −f [(N(e) − N)ᵀ (d × μ_Ω) + r''[·, μ_e]ᵀ d]
      const auto k = in.kin->at(e, nullptr, false);
      k.rows_t(-gi * in.d.cross(muW), de);
      k.second_t(mue, -gi * in.d, de);
    }
    if (dc && in.coefficient >= 0) {
      double q = mu.dot(in.q0);
      if (in.arm) q += muW.dot(Vector3d(in.N * fr.e).cross(in.d));
      if (in.kin) {
        const auto k = in.kin->at(e, nullptr, false);
        q += muW.dot(k.offset.cross(in.d)) + in.d.dot(k.rows(mue));
      }
      (*dc)[in.coefficient] -= fi * q;
    }
  }
}

// f = [R V; J_r⁻¹ Ω; ė; a], a = M⁻¹ (Q − b − D ė − K e): with μ = M⁻¹ λ_u (M symmetric),
// λ_uᵀ da = −ds for s = μᵀ R(y, a) at fixed a, so (∂f/∂y)ᵀ λ =
//   X: 0;   φ: J_rᵀ [V]× Rᵀ λ_X + ∇_φ (λ_φᵀ J_r⁻¹(φ) Ω);   e: −∂s/∂e;
//   V: Rᵀ λ_X − ∂s/∂V;   Ω: J_r⁻ᵀ λ_φ − ∂s/∂Ω;   ė: λ_e − ∂s/∂ė.
// The φ-gradient of λ_φᵀ J_r⁻¹(φ) Ω is taken by central differences (3 × 3 evaluations; relative
// error ~1e-10).
VectorXd ScoleNonlinear::Dynamics::derivative_vjp(const double* y, const VectorXd& fin, const VectorXd& ydot,
                                                  const VectorXd& lambda) const {
  const int ne = g_->ne_;
  const StateView s(y, ne);
  const Vector3d lX = lambda.head<3>(), lphi = lambda.segment<3>(3);
  const VectorXd le = lambda.segment(6, ne), lu = lambda.tail(6 + ne);
  const VectorXd e = s.e;
  const VectorXd a = ydot.tail(6 + ne);
  const auto kin = kinematics(e, true);
  const VectorXd mu = solve_mass(e, lu, kin);
  VectorXd de, du;
  residual_vjp(y, a, mu, fin, de, du, nullptr, kin);
  const Matrix3d R = rotation_matrix(s.phi);
  VectorXd out = VectorXd::Zero(g_->state_size());
  Vector3d gphi = right_jacobian(s.phi).transpose() * (skew(s.V) * (R.transpose() * lX));
  const double h = 1e-6 * std::max(1.0, s.phi.norm());
  for (int k = 0; k < 3; ++k) {
    const Vector3d dp = h * Vector3d::Unit(k);
    const Vector3d phi = s.phi;
    gphi[k] += lphi.dot((right_jacobian_inverse(phi + dp) - right_jacobian_inverse(phi - dp)) * s.Omega) / (2 * h);
  }
  out.segment<3>(3) = gphi;
  out.segment(6, ne) = -de;
  out.segment<3>(6 + ne) = R.transpose() * lX - du.head<3>();
  out.segment<3>(9 + ne) = right_jacobian_inverse(s.phi).transpose() * lphi - du.segment<3>(3);
  out.tail(ne) = le - du.tail(ne);
  return out;
}

VectorXd ScoleNonlinear::Dynamics::coefficient_vjp(const double* y, const VectorXd& fin, const VectorXd& ydot,
                                                   const VectorXd& lambda) const {
  const int ne = g_->ne_;
  const StateView s(y, ne);
  const VectorXd e = s.e;
  const auto kin = kinematics(e, true);
  const VectorXd mu = solve_mass(e, VectorXd(lambda.tail(6 + ne)), kin);
  VectorXd de, du, dc;
  residual_vjp(y, ydot.tail(6 + ne), mu, fin, de, du, &dc, kin);
  return -dc;
}

// Per sensor, ρ_k times (see outputs()):
//   shuttle rotation φ·d: ∂φ = d;  displacement X·d: ∂X = d;  velocity (R V)·d: ∂V = Rᵀd,
//   ∂φ = J_rᵀ [V]× Rᵀ d;  acceleration (R q)·d, q = V̇ + Ω × V: ∂φ = J_rᵀ [q]× Rᵀ d and, with
//   w = Rᵀ d, ∂V̇ = w, ∂Ω = V × w, ∂V = w × Ω;  rows on e or ė: the row;
//   point acceleration d·(V̇ + Ω̇ × r + N ë + Ω × V + Ω × (Ω × r) + 2 Ω × N ė):
//   ∂V̇ = d, ∂Ω̇ = r × d, ∂ë = Nᵀd, ∂V = d × Ω, ∂Ω = V × d + d (Ω·r) + r (d·Ω) − 2 (d·r) Ω + 2 (N ė) × d,
//   ∂ė = 2 Nᵀ (d × Ω), ∂e = Nᵀ (d × Ω̇ + Ω × (Ω × d)).
void ScoleNonlinear::Dynamics::outputs_vjp(const double* y, const VectorXd& udot, const VectorXd& rho, VectorXd& dy,
                                           VectorXd& da) const {
  const int ne = g_->ne_;
  const StateView s(y, ne);
  dy = VectorXd::Zero(g_->state_size());
  da = VectorXd::Zero(6 + ne);
  const Vector3d V = s.V, W = s.Omega, Vd = udot.head<3>(), Wd = udot.segment<3>(3);
  using K = Sensor::Kind;
  for (int k = 0; k < g_->sensors(); ++k) {
    const auto& se = g_->sensors_[static_cast<std::size_t>(k)];
    const double c = rho[k];
    if (c == 0.0) continue;
    const Vector3d d = c * se.d;
    switch (se.kind) {
      case K::ShuttleRotation: dy.segment<3>(3) += d; break;
      case K::ShuttleDisplacement: dy.head<3>() += d; break;
      case K::ShuttleVelocity: {
        const Matrix3d R = rotation_matrix(s.phi);
        dy.segment<3>(6 + ne) += R.transpose() * d;
        dy.segment<3>(3) += right_jacobian(s.phi).transpose() * (skew(V) * (R.transpose() * d));
        break;
      }
      case K::ShuttleAcceleration: {
        const Matrix3d R = rotation_matrix(s.phi);
        const Vector3d q = Vd + W.cross(V), w = R.transpose() * d;
        dy.segment<3>(3) += right_jacobian(s.phi).transpose() * (skew(q) * w);
        da.head<3>() += w;
        dy.segment<3>(9 + ne) += V.cross(w);
        dy.segment<3>(6 + ne) += w.cross(W);
        break;
      }
      case K::Row: dy.segment(6, ne) += c * se.row.transpose(); break;
      case K::RateRow: dy.tail(ne) += c * se.row.transpose(); break;
      case K::PointAcceleration: {
        Vector3d r = se.p + se.N * s.e, n = se.N * s.edot;
        const VectorXd ed = s.edot, edd = udot.tail(ne);
        Kinematics::At k;
        if (se.kin) {
          k = se.kin->at(s.e);
          r += k.offset;
          n += k.rows(ed);
        }
        da.head<3>() += d;
        da.segment<3>(3) += r.cross(d);
        da.tail(ne) += se.N.transpose() * d;
        dy.segment<3>(6 + ne) += d.cross(W);
        dy.segment<3>(9 + ne) += V.cross(d) + d * W.dot(r) + r * d.dot(W) - 2.0 * d.dot(r) * W + 2.0 * n.cross(d);
        dy.tail(ne) += 2.0 * (se.N.transpose() * d.cross(W));
        const Vector3d dr = d.cross(Wd) + W.cross(W.cross(d));  // ∂/∂r
        dy.segment(6, ne) += se.N.transpose() * dr;
        if (se.kin) {
          // N(e) for N in ∂ë, ∂ė and ∂r, and the e-derivative of d·(N(e) ë + 2 Ω × N(e) ė + r''[ė, ė]);
          // the convective d·r''[ė, ė] gives 2 r''[·, ė]ᵀ d on ė.
          VectorXd t_a = da.tail(ne), t_e = dy.segment(6, ne), t_d = dy.tail(ne);
          k.rows_t(d, t_a);
          k.rows_t(dr, t_e);
          k.second_t(edd, d, t_e);
          k.second_t(ed, 2.0 * d.cross(W), t_e);
          k.convective_t(ed, d, t_e);
          k.rows_t(2.0 * d.cross(W), t_d);
          k.second_t(ed, 2.0 * d, t_d);
          da.tail(ne) = t_a;
          dy.segment(6, ne) = t_e;
          dy.tail(ne) = t_d;
        }
        break;
      }
    }
  }
}

}  // namespace scoleid::identify
