// The nonlinear SCOLE model's kinematics: compact rows, a point's and a rotor's motion with the
// section, the turned inertia (scole_nonlinear.h).
#include "parts.h"

namespace scoleid::identify {

using Eigen::Matrix3d;
using Eigen::Vector3d;

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

}  // namespace scoleid::identify
