// The nonlinear SCOLE model at given coefficients: the strain energy's coupling terms, the points'
// kinematics and the rigid and foreshortening rows (scole_nonlinear.h).
#include "parts.h"

namespace scoleid::identify {

using Eigen::Matrix3d;
using Eigen::Vector3d;

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
  elastic_mass(d);
  d.K_ = MatrixXd::Zero(ne_, ne_);
  d.D_ = MatrixXd::Zero(ne_, ne_);
  for (const auto& t : stiffness_) d.K_ += scale(t.coefficient) * MatrixXd(t.matrix);
  for (const auto& t : damping_) d.D_ += scale(t.coefficient) * MatrixXd(t.matrix);
  d.k_roll_ = scale(ScoleFE::kEIRoll);
  d.k_pitch_ = scale(ScoleFE::kEIPitch);
  d.k_twist_ = scale(ScoleFE::kGJ);
  return d;
}

// The elastic mass block's pattern (with every slot a turned rotor or a nonlinear point fills),
// each rotor's and point's slots in it, and its factor at e = 0 (checked positive definite).
void ScoleNonlinear::elastic_mass(Dynamics& d) const {
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
    throw std::domain_error("ScoleNonlinear::at: the elastic mass block is not positive definite");
  d.C_ = C;
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

}  // namespace scoleid::identify
