// The nonlinear SCOLE model's mass matrix and its solves: the Schur complement on the rigid block
// and the axial inertia by preconditioned conjugate gradients (scole_nonlinear.h).
#include "parts.h"

namespace scoleid::identify {

using Eigen::Matrix3d;
using Eigen::Vector3d;

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

}  // namespace scoleid::identify
