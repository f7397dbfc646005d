// The nonlinear SCOLE model's equations of motion, their Jacobians and vector-Jacobian products,
// and its outputs (scole_nonlinear.h).
#include "parts.h"

namespace scoleid::identify {

using Eigen::Matrix3d;
using Eigen::Vector3d;

namespace {
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

// P⊥ v: Aᵀ w = Θᵀ P⊥ w (the tilt's rows are Θ's first two).
Vector3d tilt_of(const Vector3d& v) { return {v[0], v[1], 0.0}; }
}  // namespace

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
