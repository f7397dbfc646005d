#include "scoleid/identify/fe/scole_model.h"

#include <stdexcept>
#include <algorithm>
#include <cmath>
#include <complex>

#include "scoleid/identify/fe/hermite_beam.h"
#include "scoleid/io/error.h"

namespace scoleid::identify {

using Eigen::Vector3d;
using io::format_value;

namespace {

using Trip = Eigen::Triplet<double>;

enum Shuttle { kX = 0, kY, kZ, kTx, kTy, kTz };
constexpr int kNodeDofs = 5;

int full_node(int node, int field) { return 6 + kNodeDofs * node + field; }
int full_proof(int elements, int k, int axis) { return 6 + kNodeDofs * (elements + 1) + 2 * k + axis; }

// Element containing s and the local coordinate ξ ∈ [0, 1].
int element_of(double s, double L, int ne, double& xi) {
  const double h = L / ne;
  const int e = std::clamp(static_cast<int>(std::floor(s / h)), 0, ne - 1);
  xi = (s - e * h) / h;
  return e;
}

Vector3d vec3(const std::vector<double>& v) { return {v[0], v[1], v[2]}; }

Eigen::Matrix3d inertia_matrix(const io::RigidBodySpec& b) {
  // Products as the off-diagonal entries, as Simbody's Inertia(moments, products) takes them.
  Eigen::Matrix3d I;
  I << b.Ixx, b.Ixy, b.Ixz, b.Ixy, b.Iyy, b.Iyz, b.Ixz, b.Iyz, b.Izz;
  return I;
}

// Rows on the full DOF vector (3 × nfull).
class FullRows {
public:
  FullRows(const io::ScoleSpec& sc, int elements, int nfull) : sc_(sc), ne_(elements), nfull_(nfull) {}

  MatrixXd zero() const { return MatrixXd::Zero(3, nfull_); }

  // Axial displacement of any mast point: rigid with the shuttle.
  Eigen::RowVectorXd axial() const {
    Eigen::RowVectorXd a = Eigen::RowVectorXd::Zero(nfull_);
    a[kZ] = 1.0;
    a[kTx] = sc_.mast_root[1];
    a[kTy] = -sc_.mast_root[0];
    return a;
  }
  // The element e holding mast station s, its local coordinate xi and the four Hermite functions
  // there (`basis`: hermite::shape or hermite::slope); `add(ux, uy, value)` gets each one's full
  // DOF indices in the two bending planes.
  template <class Basis, class Add>
  int hermite_row(double s, Basis basis, double& xi, Add add) const {
    const int e = element_of(s, sc_.length, ne_, xi);
    const hermite::Vec4 f = basis(xi, sc_.length / ne_);
    for (int a = 0; a < 4; ++a) {
      const int node = e + a / 2, slope = a % 2;
      add(full_node(node, ScoleFE::kUx + slope), full_node(node, ScoleFE::kUy + slope), f[a]);
    }
    return e;
  }
  // Absolute displacement (u_x, u_y, w) of mast station s.
  MatrixXd displacement(double s) const {
    MatrixXd R = zero();
    double xi = 0.0;
    hermite_row(s, hermite::shape, xi, [&](int ux, int uy, double n) {
      R(0, ux) += n;
      R(1, uy) += n;
    });
    R.row(2) = axial();
    return R;
  }
  // Absolute cross-section rotation Θ = (u_y', −u_x', ψ) at s.
  MatrixXd rotation(double s) const {
    MatrixXd R = zero();
    double xi = 0.0;
    const int e = hermite_row(s, hermite::slope, xi, [&](int ux, int uy, double d) {
      R(0, uy) += d;
      R(1, ux) -= d;
    });
    R(2, full_node(e, ScoleFE::kPsi)) += 1.0 - xi;
    R(2, full_node(e + 1, ScoleFE::kPsi)) += xi;
    return R;
  }
  // a × r for rows a (3 × n) and a constant vector r.
  static MatrixXd cross(const MatrixXd& a, const Vector3d& r) {
    MatrixXd c(3, a.cols());
    c.row(0) = a.row(1) * r[2] - a.row(2) * r[1];
    c.row(1) = a.row(2) * r[0] - a.row(0) * r[2];
    c.row(2) = a.row(0) * r[1] - a.row(1) * r[0];
    return c;
  }
  Vector3d reflector_offset() const { return {sc_.reflector_rx, sc_.reflector_ry, 0.0}; }
  // Reflector CM: u(L) + Θ(L) × r.
  MatrixXd reflector() const { return displacement(sc_.length) + cross(rotation(sc_.length), reflector_offset()); }
  MatrixXd shuttle_rotation() const {
    MatrixXd R = zero();
    for (int i = 0; i < 3; ++i) R(i, kTx + i) = 1.0;
    return R;
  }
  // X + θ × p0 (a point fixed to the shuttle at p0 from its CM).
  MatrixXd shuttle_rigid(const Vector3d& p0) const {
    MatrixXd R = cross(shuttle_rotation(), p0);
    for (int i = 0; i < 3; ++i) R(i, kX + i) += 1.0;
    return R;
  }
  Vector3d mast_point(double s) const { return vec3(sc_.mast_root) - s * Vector3d::UnitZ(); }
  Vector3d reflector_point() const { return mast_point(sc_.length) + reflector_offset(); }

private:
  const io::ScoleSpec& sc_;
  int ne_, nfull_;
};

// Adds rowsᵀ W rows (rows k × nfull, mostly zero) to a triplet list.
void add_quadratic(std::vector<Trip>& out, const MatrixXd& rows, const MatrixXd& W) {
  std::vector<int> cols;
  for (int j = 0; j < rows.cols(); ++j)
    if (rows.col(j).cwiseAbs().maxCoeff() != 0.0) cols.push_back(j);
  const MatrixXd Wr = W * rows;
  for (int a : cols)
    for (int b : cols) {
      const double v = rows.col(a).dot(Wr.col(b));
      if (v != 0.0) out.emplace_back(a, b, v);
    }
}

}  // namespace

int ScoleFE::node_dof(int node, Field f) const { return node_reduced[static_cast<std::size_t>(kNodeDofs * node + f)]; }

// The reduced rows are the full rows times T; FullRows only needs the geometry.
MatrixXd ScoleFE::mast_displacement(double s) const { return FullRows(spec, elements, nfull).displacement(s) * T; }
MatrixXd ScoleFE::mast_rotation(double s) const { return FullRows(spec, elements, nfull).rotation(s) * T; }
MatrixXd ScoleFE::reflector_displacement() const { return FullRows(spec, elements, nfull).reflector() * T; }
MatrixXd ScoleFE::shuttle_rigid_displacement(const Vector3d& p0) const {
  return FullRows(spec, elements, nfull).shuttle_rigid(p0) * T;
}
MatrixXd ScoleFE::shuttle_rotation() const { return FullRows(spec, elements, nfull).shuttle_rotation() * T; }

VectorXd ScoleFE::rigid_motion(const Vector3d& a, const Vector3d& theta) const {
  VectorXd u = VectorXd::Zero(model.ndof);
  for (int i = 0; i < 3; ++i) {
    u[shuttle_dof(kX + i)] = a[i];
    u[shuttle_dof(kTx + i)] = theta[i];
  }
  const FullRows fr(spec, elements, nfull);
  const double h = spec.length / elements;
  for (int n = 1; n <= elements; ++n) {
    const Vector3d d = a + theta.cross(fr.mast_point(n * h));
    u[node_dof(n, kUx)] = d[0];
    u[node_dof(n, kUxSlope)] = -theta[1];
    u[node_dof(n, kUy)] = d[1];
    u[node_dof(n, kUySlope)] = theta[0];
    u[node_dof(n, kPsi)] = theta[2];
  }
  for (std::size_t k = 0; k < spec.actuator_locations.size(); ++k) {
    const Vector3d d = a + theta.cross(fr.mast_point(spec.actuator_locations[k]));
    for (int ax = 0; ax < 2; ++ax) u[proof_mass_dof(static_cast<int>(k), ax)] = d[ax];
  }
  return u;
}

namespace {

// The full-vector operators' triplets, one list per coefficient (docs/theory.md §3.3–3.7).
struct FullOperators {
  std::vector<Trip> mass_bend, mass_tors, stiff_roll, stiff_pitch, stiff_tors, mass_const, mass_refl;
  std::vector<Trip> damp_roll, damp_pitch, act_spring;
};

// A scenario that passed io::validate_scenario holds only what the model reads (io/scole_kind.cpp,
// check); anything else here is a caller's defect. The actuator force enters the equations as
// commanded (no servo state): a servo lag is the truth's alone, refused by the identifier's door
// (identify/door) and by io::check_fe_reproduces_truth where the model stands for the truth.
[[noreturn]] void unchecked(const std::string& what) {
  throw std::logic_error("build_scole: " + what + " is not one the SCOLE model reads (io::validate_scenario refuses it)");
}

void check_spec(const io::ScoleSpec& sc, int elements) {
  if (elements < 1) unchecked(std::to_string(elements) + " elements");
  if (sc.mast_root.size() != 3) unchecked("scole.mast_root");
}

// Reduced order: nodes 1..n (proof masses after their nearest node) | X, Y, Z, θx, θy, θz; and T:
// identity on the kept DOFs, the root node expressed in the shuttle's rigid motion.
void order_dofs(ScoleFE& fe) {
  const io::ScoleSpec& sc = fe.spec;
  const int ne = fe.elements;
  const int nact = static_cast<int>(sc.actuator_locations.size());
  const double h = sc.length / ne;
  std::vector<int> order;  // full index of each reduced DOF
  std::vector<std::vector<int>> after(static_cast<std::size_t>(ne + 1));
  for (int k = 0; k < nact; ++k) {
    const int node = std::clamp(static_cast<int>(std::lround(sc.actuator_locations[static_cast<std::size_t>(k)] / h)), 1, ne);
    after[static_cast<std::size_t>(node)].push_back(k);
  }
  for (int n = 1; n <= ne; ++n) {
    for (int f = 0; f < kNodeDofs; ++f) order.push_back(full_node(n, f));
    for (int k : after[static_cast<std::size_t>(n)])
      for (int ax = 0; ax < 2; ++ax) order.push_back(full_proof(ne, k, ax));
  }
  for (int i : {kX, kY, kZ, kTx, kTy, kTz}) order.push_back(i);
  const int n = static_cast<int>(order.size());
  std::vector<int> reduced_of(static_cast<std::size_t>(fe.nfull), -1);
  for (int r = 0; r < n; ++r) reduced_of[static_cast<std::size_t>(order[static_cast<std::size_t>(r)])] = r;
  for (int i = 0; i < 6; ++i) fe.shuttle_reduced.push_back(reduced_of[static_cast<std::size_t>(i)]);
  for (int nd = 0; nd <= ne; ++nd)
    for (int f = 0; f < kNodeDofs; ++f) fe.node_reduced.push_back(reduced_of[static_cast<std::size_t>(full_node(nd, f))]);
  for (int k = 0; k < nact; ++k)
    for (int ax = 0; ax < 2; ++ax) fe.proof_reduced.push_back(reduced_of[static_cast<std::size_t>(full_proof(ne, k, ax))]);

  std::vector<Trip> t;
  for (int r = 0; r < n; ++r) t.emplace_back(order[static_cast<std::size_t>(r)], r, 1.0);
  const Vector3d r0 = vec3(sc.mast_root);
  auto S = [&](int i) { return fe.shuttle_reduced[static_cast<std::size_t>(i)]; };
  t.emplace_back(full_node(0, ScoleFE::kUx), S(kX), 1.0);
  t.emplace_back(full_node(0, ScoleFE::kUx), S(kTy), r0[2]);
  t.emplace_back(full_node(0, ScoleFE::kUx), S(kTz), -r0[1]);
  t.emplace_back(full_node(0, ScoleFE::kUxSlope), S(kTy), -1.0);
  t.emplace_back(full_node(0, ScoleFE::kUy), S(kY), 1.0);
  t.emplace_back(full_node(0, ScoleFE::kUy), S(kTz), r0[0]);
  t.emplace_back(full_node(0, ScoleFE::kUy), S(kTx), -r0[2]);
  t.emplace_back(full_node(0, ScoleFE::kUySlope), S(kTx), 1.0);
  t.emplace_back(full_node(0, ScoleFE::kPsi), S(kTz), 1.0);
  fe.T.resize(fe.nfull, n);
  fe.T.setFromTriplets(t.begin(), t.end());
  fe.T.makeCompressed();
}

// The mast's elements: Hermite bending in both planes, linear torsion, and the slope quadratic
// forms (docs/theory.md §3.3, §4.3): G_roll = ∫ (Θx − θx)², G_pitch = ∫ (Θy − θy)² on the
// cross-section rotation relative to the shuttle (the damping's dissipation), and ½ ∫ (Θx² + Θy²)
// on the absolute one (the section's bending rotary inertia ρI_ψ/2 per plane).
void add_mast_elements(FullOperators& o, const io::ScoleSpec& sc, int ne, const FullRows& fr) {
  const double h = sc.length / ne;
  const hermite::Mat4 Me = hermite::mass(h, 0.0, h), Ke = hermite::stiffness(h, 0.0, h);
  // Three-point Gauss rule on [0, 1]: exact for the quadratic-times-quadratic slope products.
  const double g = 0.5 * std::sqrt(0.6);
  const double gauss_x[3] = {0.5 - g, 0.5, 0.5 + g}, gauss_w[3] = {5.0 / 18.0, 8.0 / 18.0, 5.0 / 18.0};
  const MatrixXd shuttle_rot = fr.shuttle_rotation();
  for (int e = 0; e < ne; ++e) {
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b) {
        const int ax = full_node(e + a / 2, ScoleFE::kUx + a % 2), bx = full_node(e + b / 2, ScoleFE::kUx + b % 2);
        const int ay = full_node(e + a / 2, ScoleFE::kUy + a % 2), by = full_node(e + b / 2, ScoleFE::kUy + b % 2);
        o.mass_bend.emplace_back(ax, bx, Me(a, b));
        o.mass_bend.emplace_back(ay, by, Me(a, b));
        o.stiff_pitch.emplace_back(ax, bx, Ke(a, b));
        o.stiff_roll.emplace_back(ay, by, Ke(a, b));
      }
    // Linear torsion element: ∫ N Nᵀ = h/6 [2 1; 1 2], ∫ N' N'ᵀ = 1/h [1 −1; −1 1].
    for (int a = 0; a < 2; ++a)
      for (int b = 0; b < 2; ++b) {
        const int pa = full_node(e + a, ScoleFE::kPsi), pb = full_node(e + b, ScoleFE::kPsi);
        o.mass_tors.emplace_back(pa, pb, h / 6.0 * (a == b ? 2.0 : 1.0));
        o.stiff_tors.emplace_back(pa, pb, (a == b ? 1.0 : -1.0) / h);
      }
    for (int q = 0; q < 3; ++q) {
      const MatrixXd rot = fr.rotation((e + gauss_x[q]) * h);
      const MatrixXd rel = rot - shuttle_rot;
      const double w = gauss_w[q] * h;
      add_quadratic(o.damp_roll, rel.row(0), MatrixXd::Constant(1, 1, w));
      add_quadratic(o.damp_pitch, rel.row(1), MatrixXd::Constant(1, 1, w));
      if (sc.bending_rotary_inertia) add_quadratic(o.mass_tors, rot.topRows(2), 0.5 * w * MatrixXd::Identity(2, 2));
    }
  }
}

// The bodies: the mast's rigid axial motion (ρA L w²), the shuttle, the reflector (translation of
// its CM and rotation of the tip section), the proof masses (laterally on their sliders with the
// centering spring and damper on the stroke ξ − u(s_k), §3.7; axially with the mast).
void add_bodies(FullOperators& o, const io::ScoleSpec& sc, int ne, const FullRows& fr) {
  add_quadratic(o.mass_bend, fr.axial(), MatrixXd::Constant(1, 1, sc.length));
  MatrixXd tr = fr.zero();
  for (int i = 0; i < 3; ++i) tr(i, kX + i) = 1.0;
  add_quadratic(o.mass_const, tr, sc.shuttle.mass * MatrixXd::Identity(3, 3));
  add_quadratic(o.mass_const, fr.shuttle_rotation(), inertia_matrix(sc.shuttle));
  add_quadratic(o.mass_refl, fr.reflector(), MatrixXd::Identity(3, 3));  // × m_reflector
  add_quadratic(o.mass_const, fr.rotation(sc.length), inertia_matrix(sc.reflector));
  for (int k = 0; k < static_cast<int>(sc.actuator_locations.size()); ++k) {
    MatrixXd p = fr.zero();
    p(0, full_proof(ne, k, 0)) = 1.0;
    p(1, full_proof(ne, k, 1)) = 1.0;
    p.row(2) = fr.axial();
    add_quadratic(o.mass_const, p, sc.actuator_mass * MatrixXd::Identity(3, 3));
    MatrixXd stroke = p - fr.displacement(sc.actuator_locations[static_cast<std::size_t>(k)]);
    add_quadratic(o.act_spring, stroke.topRows(2), MatrixXd::Identity(2, 2));
  }
}

// The structural model's operators: the full ones reduced by T, each with its coefficient.
void assemble_operators(ScoleFE& fe, const FullOperators& o) {
  StructuralModel& m = fe.model;
  const int n = static_cast<int>(fe.T.cols());
  m.ndof = n;
  m.ncoef = ScoleFE::kCount;
  m.coefficient_names = {"rho_A",  "EI_roll", "EI_pitch",    "GJ",         "rho_I_psi", "d_roll",
                         "d_pitch", "c_tors", "m_reflector", "k_actuator", "c_actuator"};
  m.dof_group.assign(static_cast<std::size_t>(n), 0);  // 0: displacements [ft], 1: rotations [rad]
  for (int i : {kTx, kTy, kTz}) m.dof_group[static_cast<std::size_t>(fe.shuttle_dof(i))] = 1;
  for (int nd = 1; nd <= fe.elements; ++nd)
    for (auto f : {ScoleFE::kUxSlope, ScoleFE::kUySlope, ScoleFE::kPsi})
      m.dof_group[static_cast<std::size_t>(fe.node_dof(nd, f))] = 1;
  auto reduce = [&](const std::vector<Trip>& t) {
    SparseMatrix F(fe.nfull, fe.nfull);
    F.setFromTriplets(t.begin(), t.end());
    SparseMatrix R = SparseMatrix(fe.T.transpose()) * F * fe.T;
    R.prune(0.0);
    R.makeCompressed();
    return R;
  };
  const SparseMatrix Kr = reduce(o.stiff_roll), Kp = reduce(o.stiff_pitch), Kt = reduce(o.stiff_tors);
  const SparseMatrix Ka = reduce(o.act_spring);
  m.mass = {{reduce(o.mass_bend), ScoleFE::kRhoA},
            {reduce(o.mass_tors), ScoleFE::kRhoIPsi},
            {reduce(o.mass_refl), ScoleFE::kMReflector},
            {reduce(o.mass_const), -1}};
  m.stiffness = {{Kr, ScoleFE::kEIRoll}, {Kp, ScoleFE::kEIPitch}, {Kt, ScoleFE::kGJ}};
  m.damping = {{reduce(o.damp_roll), ScoleFE::kDRoll}, {reduce(o.damp_pitch), ScoleFE::kDPitch}, {Kt, ScoleFE::kCTors}};
  if (!fe.spec.actuator_locations.empty()) {
    m.stiffness.push_back({Ka, ScoleFE::kKActuator});
    m.damping.push_back({Ka, ScoleFE::kCActuator});
  }
}

Vector3d given_direction(const std::vector<double>& d, const std::string& field) {
  const Vector3d v = vec3(d);
  if (!(v.norm() > 0.0)) unchecked(field);
  return v;
}
void check_station(double s, double L, const std::string& field) {
  if (!(s >= 0.0 && s <= L)) unchecked(field);
}

// The rows (3 × nfull) a point input acts through: its work is fᵀ (rows u) along its direction.
MatrixXd input_rows(const ScoleFE& fe, const FullRows& fr, const io::InputSpec& in, const Vector3d& d, const std::string& f) {
  const io::ScoleSpec& sc = fe.spec;
  const int nact = static_cast<int>(sc.actuator_locations.size());
  const double L = sc.length;
  const bool moment = in.kind == io::InputKind::Moment;
  if (in.at == io::Site::Shuttle) return moment ? fr.shuttle_rotation() : fr.shuttle_rigid(Vector3d::Zero());
  if (in.at == io::Site::Reflector) return moment ? fr.rotation(L) : fr.reflector();
  if (in.at == io::Site::Mast) {
    check_station(in.location, L, f + ".location");
    return moment ? fr.rotation(in.location) : fr.displacement(in.location);
  }
  if (const int k = io::actuator_index(in.at); k >= 0) {
    if (k >= nact) unchecked(f + ".at");
    if (moment) unchecked(f + ".kind");
    if (std::abs(d[2]) > 1e-12)
      unchecked(f + ".direction");
    // Slider force: +f on the proof mass, −f on the mast at s_k.
    MatrixXd rows = -fr.displacement(sc.actuator_locations[static_cast<std::size_t>(k)]);
    rows.row(2).setZero();
    rows(0, full_proof(fe.elements, k, 0)) += 1.0;
    rows(1, full_proof(fe.elements, k, 1)) += 1.0;
    return rows;
  }
  unchecked(f + ".at");
}

// A rate sensor's row: velocity, d/dt of the displacement sensor's quantity (relative to the
// shuttle frame; the shuttle's own CM in ground), a row on u̇; acceleration, the inertial
// acceleration of the point along d (an accelerometer), the absolute displacement's row on ü.
Eigen::RowVectorXd rate_sensor_row(const FullRows& fr, const io::SensorSpec& se, const Vector3d& d, int order, double L,
                                   const std::string& f) {
  if (se.at != io::Site::Shuttle && se.at != io::Site::Mast && se.at != io::Site::Reflector)
    unchecked(f + ".at");
  const bool mast = se.at == io::Site::Mast;
  if (mast) check_station(se.location, L, f + ".location");
  const MatrixXd absolute = se.at == io::Site::Shuttle ? fr.shuttle_rigid(Vector3d::Zero())
                            : mast           ? fr.displacement(se.location)
                                             : fr.reflector();
  const Vector3d p0 = mast ? fr.mast_point(se.location) : fr.reflector_point();
  return d.transpose() * (order == 2 || se.at == io::Site::Shuttle ? absolute : MatrixXd(absolute - fr.shuttle_rigid(p0)));
}

// A displacement, rotation or line-of-sight sensor's row on u: the shuttle's against ground, the
// mast's and the reflector's relative to the shuttle frame.
Eigen::RowVectorXd position_sensor_row(const ScoleFE& fe, const FullRows& fr, const io::SensorSpec& se, const Vector3d& d,
                                       const std::string& f) {
  const double L = fe.spec.length;
  if (se.at == io::Site::Shuttle) {
    if (se.kind == io::SensorKind::LineOfSight)
      unchecked(f + ".kind");
    return d.transpose() * (se.kind == io::SensorKind::Rotation ? fr.shuttle_rotation() : fr.shuttle_rigid(Vector3d::Zero()));
  }
  if (se.at != io::Site::Mast && se.at != io::Site::Reflector)
    unchecked(f + ".at");
  const bool mast = se.at == io::Site::Mast;
  if (mast) check_station(se.location, L, f + ".location");
  const Vector3d p0 = mast ? fr.mast_point(se.location) : fr.reflector_point();
  if (se.kind == io::SensorKind::Rotation) return d.transpose() * ((mast ? fr.rotation(se.location) : fr.rotation(L)) - fr.shuttle_rotation());
  const MatrixXd rel = (mast ? fr.displacement(se.location) : fr.reflector()) - fr.shuttle_rigid(p0);
  if (se.kind == io::SensorKind::Displacement) return d.transpose() * rel;
  const Vector3d chord = p0 - vec3(fe.spec.mast_root);
  const double ell = chord.norm();
  if (!(ell > 0.0))
    unchecked(f + ".location");
  const Vector3d u0 = chord / ell;
  return d.cross(u0).transpose() * rel / ell;
}

ModelSensor sensor_of(const ScoleFE& fe, const FullRows& fr, const io::SensorSpec& se, const std::string& f) {
  const Vector3d d = given_direction(se.direction, f + ".direction");
  ModelSensor ms;
  ms.name = se.name;
  ms.kind = se.kind;
  Eigen::RowVectorXd row;
  if (io::derivative_order(se.kind) > 0) {
    ms.order = io::derivative_order(se.kind);
    row = rate_sensor_row(fr, se, d, ms.order, fe.spec.length, f);
  } else if (!io::reads(io::Structure::Scole, se.kind)) {
    unchecked(f + ".kind");
  } else {
    row = position_sensor_row(fe, fr, se, d, f);
  }
  ms.row = row * fe.T;
  return ms;
}

}  // namespace

ScoleFE build_scole(const io::ScoleSpec& sc, int elements, const std::vector<io::InputSpec>& inputs,
                    const std::vector<io::SensorSpec>& sensors) {
  check_spec(sc, elements);
  ScoleFE fe;
  fe.spec = sc;
  fe.elements = elements;
  fe.nfull = 6 + kNodeDofs * (elements + 1) + 2 * static_cast<int>(sc.actuator_locations.size());
  order_dofs(fe);
  const FullRows fr(sc, elements, fe.nfull);
  FullOperators ops;
  add_mast_elements(ops, sc, elements, fr);
  add_bodies(ops, sc, elements, fr);
  assemble_operators(fe, ops);
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    const std::string f = "inputs[" + std::to_string(i) + "]";
    const Vector3d d = given_direction(inputs[i].direction, f + ".direction");
    ModelInput mi;
    mi.name = inputs[i].name;
    mi.vector = SparseMatrix(fe.T.transpose()) * (input_rows(fe, fr, inputs[i], d, f).transpose() * d);
    fe.model.inputs.push_back(std::move(mi));
  }
  for (std::size_t k = 0; k < sensors.size(); ++k)
    fe.model.sensors.push_back(sensor_of(fe, fr, sensors[k], "sensors[" + std::to_string(k) + "]"));
  return fe;
}

namespace {
// Torsion's Kelvin–Voigt coefficient per unit ζ·√(ρI_ψ GJ): 2 · 2L/π, so that the first
// clamped–free torsion mode of the uniform mast has damping ratio ζ (docs/theory.md §3.3).
double torsion_scale(double L) { return 4.0 * L / M_PI; }
}  // namespace

VectorXd scole_coefficients(const io::ScoleSpec& s) {
  VectorXd c(ScoleFE::kCount);
  c << s.rho_A, s.EI_roll, s.EI_pitch, s.GJ, s.rho_I_psi, 2.0 * s.zeta * std::sqrt(s.rho_A * s.EI_roll),
      2.0 * s.zeta * std::sqrt(s.rho_A * s.EI_pitch), torsion_scale(s.length) * s.zeta * std::sqrt(s.rho_I_psi * s.GJ),
      s.reflector.mass, s.actuator_stiffness, s.actuator_damping;
  return c;
}

// ---------------------------------------------------------------------------------------------

ParameterSpace scole_parameter_space(const io::ScoleSpec& sc) {
  ParameterSpace sp;
  sp.structure = "SCOLE";
  sp.quantities = {"rho_A", "EI_roll", "EI_pitch", "GJ", "rho_I_psi", "zeta", "m_reflector", "k_actuator", "c_actuator"};
  sp.value = {sc.rho_A, sc.EI_roll, sc.EI_pitch, sc.GJ, sc.rho_I_psi, sc.zeta, sc.reflector.mass,
              sc.actuator_stiffness, sc.actuator_damping};
  sp.true_value.assign(sp.quantities.size(), true);
  sp.groups = {{"EI", {1, 2}, true}};
  sp.rho_A = 0;
  sp.q3_quantity = -1;  // no q3 (has_q3 = false)
  sp.has_q3 = false;
  sp.ncoef = ScoleFE::kCount;
  // c = [ρA, EI_roll, EI_pitch, GJ, ρI_ψ, d_roll, d_pitch, c_tors, m_reflector, k_actuator,
  // c_actuator] (scole_model.h).
  const double tors = torsion_scale(sc.length);
  sp.coefficients = [tors](const std::vector<ParameterSpace::Cd>& f) {
    const auto two = ParameterSpace::Cd(2.0);
    return std::vector<ParameterSpace::Cd>{f[0], f[1], f[2], f[3], f[4], two * f[5] * std::sqrt(f[0] * f[1]),
                                           two * f[5] * std::sqrt(f[0] * f[2]), tors * f[5] * std::sqrt(f[4] * f[3]),
                                           f[6], f[7], f[8]};
  };
  return sp;
}

namespace {

class ScoleStructure final : public FEStructure {
public:
  ScoleStructure(const io::Scenario& sc, int elements)
      : fe_(build_scole(sc.scole, elements, sc.inputs, sc.sensors)) {}
  const StructuralModel& model() const override { return fe_.model; }
  int elements() const override { return fe_.elements; }
  double length() const override { return fe_.spec.length; }
  ParameterSpace parameter_space(const io::Scenario& sc) const override { return scole_parameter_space(sc.scole); }
  VectorXd coefficients(const io::Scenario& sc) const override { return scole_coefficients(sc.scole); }

private:
  ScoleFE fe_;
};

}  // namespace

std::unique_ptr<FEStructure> make_scole_structure(const io::Scenario& sc, int elements) {
  return std::make_unique<ScoleStructure>(sc, elements);
}

}  // namespace scoleid::identify
