// The nonlinear SCOLE model assembled from the FE model: the mast's, the reflector's, the shuttle's
// and the proof masses' mass points and rotors, the inputs and the sensors (scole_nonlinear.h).
#include "parts.h"

#include "scoleid/io/error.h"

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
}  // namespace

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

ScoleNonlinear scole_nonlinear(const io::Scenario& sc, int elements) {
  // A SCOLE scenario's mast is uniform (identification.sections 0 or 1, io/scole_kind.cpp); the
  // callers refuse the model for other structures (io::validate_scenario, scole-crosscheck).
  if (sc.structure != io::Structure::Scole)
    throw std::logic_error("scole_nonlinear: structure '" + std::string(io::to_string(sc.structure)) + "' has no nonlinear model");
  const ScoleFE fe = build_scole(sc.scole, elements, sc.inputs, sc.sensors);
  return ScoleNonlinear(fe, sc.inputs, sc.sensors);
}

}  // namespace scoleid::identify
