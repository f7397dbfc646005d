#include "scoleid/identify/fe/beam_model.h"

#include <cmath>
#include <map>
#include <stdexcept>

#include "scoleid/identify/fe/analytic_beam.h"
#include "scoleid/identify/fe/hermite_beam.h"
#include "scoleid/io/error.h"

namespace scoleid::identify {

using io::EndCondition;
using io::format_value;

namespace {

int element_of(double s, double L, int ne, double& xi) {
  const double h = L / ne;
  int e = static_cast<int>(std::floor(s / h));
  if (e >= ne) e = ne - 1;
  if (e < 0) e = 0;
  xi = (s - e * h) / h;
  return e;
}

// The row of w (derivative 0), w_s (1) or w_ss (2) at s, from the Hermite element containing s.
Eigen::RowVectorXd field_row(const BeamFE& fe, double s, int derivative) {
  Eigen::RowVectorXd row = Eigen::RowVectorXd::Zero(fe.model.ndof);
  double xi = 0.0;
  const double h = fe.length / fe.elements;
  const int e = element_of(s, fe.length, fe.elements, xi);
  const hermite::Vec4 n = derivative == 2   ? hermite::curvature(xi, h)
                          : derivative == 1 ? hermite::slope(xi, h)
                                            : hermite::shape(xi, h);
  for (int a = 0; a < 4; ++a) {
    const int r = fe.full_to_reduced[static_cast<std::size_t>(2 * e + a)];
    if (r >= 0) row[r] += n[a];
  }
  return row;
}

}  // namespace

Eigen::RowVectorXd BeamFE::displacement_row(double s) const { return field_row(*this, s, 0); }
Eigen::RowVectorXd BeamFE::rotation_row(double s) const { return field_row(*this, s, 1); }
Eigen::RowVectorXd BeamFE::curvature_row(double s) const { return field_row(*this, s, 2); }

namespace {

// The inputs' load vectors: a force on the displacement row, a moment on the rotation row.
void add_beam_inputs(BeamFE& fe, const io::BeamSpec& beam, const std::vector<io::InputSpec>& inputs) {
  StructuralModel& m = fe.model;
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    const auto& in = inputs[i];
    const std::string f = "inputs[" + std::to_string(i) + "]";
    if (in.at != io::Site::Beam || !(in.location >= 0.0 && in.location <= beam.length))
      throw std::logic_error("build_beam: " + f + " is not on the beam (io::validate_scenario refuses it)");
    ModelInput mi;
    mi.name = in.name;
    if (!in.attachment.empty()) {  // a force on a lumped attachment's own DOF (docs/theory.md §2.5)
      const auto it = fe.lumped_dof.find(in.attachment);
      if (it == fe.lumped_dof.end())
        throw std::logic_error("build_beam: " + f + ".attachment names no lumped attachment (io::validate_scenario refuses it)");
      mi.vector = VectorXd::Unit(m.ndof, it->second);
      m.inputs.push_back(std::move(mi));
      continue;
    }
    mi.vector = (in.kind == io::InputKind::Moment ? fe.rotation_row(in.location) : fe.displacement_row(in.location)).transpose();
    m.inputs.push_back(std::move(mi));
  }
}

// A sensor's output row on u (docs/theory.md §3.5): w(s) or w_s(s); velocity and acceleration the
// displacement row, read on u̇, ü (ModelSensor::order); a strain gauge ε = −offset · w_ss, the
// Hermite curvature row (linear in each element); a relative-displacement gauge w(s) − w(reference).
Eigen::RowVectorXd beam_sensor_row(const BeamFE& fe, const io::SensorSpec& se) {
  using K = io::SensorKind;
  switch (se.kind) {
    case K::Displacement:
    case K::Velocity:
    case K::Acceleration:
      return fe.displacement_row(se.location);
    case K::Rotation:
      return fe.rotation_row(se.location);
    case K::Strain:
      return -se.field("offset") * fe.curvature_row(se.location);
    case K::RelativeDisplacement:
      return fe.displacement_row(se.location) - fe.displacement_row(se.field("reference"));
    case K::LineOfSight:
      break;
  }
  throw std::logic_error("beam_sensor_row: a sensor kind the beam does not read");
}

void add_beam_sensors(BeamFE& fe, const io::BeamSpec& beam, const std::vector<io::SensorSpec>& sensors) {
  StructuralModel& m = fe.model;
  for (std::size_t k = 0; k < sensors.size(); ++k) {
    const auto& se = sensors[k];
    const std::string f = "sensors[" + std::to_string(k) + "]";
    if (se.at != io::Site::Beam || !io::reads(io::Structure::Beam, se.kind) || !(se.location >= 0.0 && se.location <= beam.length))
      throw std::logic_error("build_beam: " + f + " is not a sensor the beam reads (io::validate_scenario refuses it)");
    ModelSensor ms;
    ms.name = se.name;
    ms.kind = se.kind;
    ms.order = io::derivative_order(se.kind);
    ms.row = beam_sensor_row(fe, se);
    m.sensors.push_back(std::move(ms));
  }
}

// The free degrees of freedom: the nodes' w and θ less those the ends' supports constrain
// (fe.full_to_reduced), then one for each lumped attachment's mass (docs/theory.md §2.5: its
// displacement along w, fe.lumped_dof). Returns their number.
int beam_dofs(BeamFE& fe, const io::BeamSpec& beam) {
  const int elements = fe.elements;
  const int nfull = 2 * (elements + 1);
  // Constrained DOFs.
  std::vector<bool> fixed(static_cast<std::size_t>(nfull), false);
  auto constrain = [&](int node, EndCondition ec) {
    if (ec == EndCondition::Pinned || ec == EndCondition::Clamped) fixed[static_cast<std::size_t>(2 * node)] = true;
    if (ec == EndCondition::Clamped) fixed[static_cast<std::size_t>(2 * node + 1)] = true;
  };
  constrain(0, beam.left);
  constrain(elements, beam.right);
  fe.full_to_reduced.assign(static_cast<std::size_t>(nfull), -1);
  int n = 0;
  for (int i = 0; i < nfull; ++i)
    if (!fixed[static_cast<std::size_t>(i)]) fe.full_to_reduced[static_cast<std::size_t>(i)] = n++;
  if (n == 0) throw std::logic_error("build_beam: " + std::to_string(elements) + " elements leave no free degree of freedom");
  // A lumped attachment's mass: a degree of freedom of its own, after the beam's.
  std::map<std::string, int>& lumped_dof = fe.lumped_dof;
  for (const auto& e : beam.attachments)
    if (e.lumped_mass > 0.0) lumped_dof[e.name] = n + static_cast<int>(lumped_dof.size());
  n += static_cast<int>(lumped_dof.size());
  return n;
}

// The coefficients: rho_A, EI and d per section, c_kv, then one per point element's quantity
// (docs/theory.md §2.5, fe.points); the DOFs' unit groups.
void beam_coefficients(BeamFE& fe, const io::BeamSpec& beam, int n) {
  const int sections = fe.sections;
  const int nfull = 2 * (fe.elements + 1);
  StructuralModel& m = fe.model;
  m.ndof = n;
  m.ncoef = 2 + 2 * sections;
  m.coefficient_names.push_back("rho_A");
  for (int s = 0; s < sections; ++s) m.coefficient_names.push_back("EI_" + std::to_string(s + 1));
  for (int s = 0; s < sections; ++s) m.coefficient_names.push_back("d_" + std::to_string(s + 1));
  m.coefficient_names.push_back("c_kv");
  // The point elements' quantities, one coefficient each after c_kv (docs/theory.md §2.5).
  for (const bool supports : {true, false})
    for (const auto& e : supports ? beam.supports : beam.attachments)
      for (const auto& [key, member] : io::point_element_fields())
        if (e.*member > 0.0) {
          fe.points.push_back({io::point_element_parameter(supports ? "supports" : "attachments", e, key), e.location,
                               std::string(key), e.*member});
          m.coefficient_names.push_back(fe.points.back().name);
        }
  m.ncoef += static_cast<int>(fe.points.size());
  m.dof_group.assign(static_cast<std::size_t>(n), 0);  // a lumped mass's DOF is a displacement
  for (int i = 0; i < nfull; ++i) {
    const int r = fe.full_to_reduced[static_cast<std::size_t>(i)];
    if (r >= 0) m.dof_group[static_cast<std::size_t>(r)] = i % 2;  // 0: w, 1: θ
  }
}

using Trip = Eigen::Triplet<double>;

SparseMatrix sparse_of(int n, const std::vector<Trip>& t) {
  SparseMatrix A(n, n);
  A.setFromTriplets(t.begin(), t.end());
  A.makeCompressed();
  return A;
}

// The distributed operators: ρA's mass, each section's stiffness and Chen–Russell slope product
// (an element split at section boundaries, so jumps of EI and d are integrated exactly), the
// Kelvin–Voigt term, the tip's mass and inertia.
void beam_operators(BeamFE& fe, const io::BeamSpec& beam, int n) {
  const int elements = fe.elements, sections = fe.sections;
  StructuralModel& m = fe.model;
  const double h = beam.length / elements;
  const double hs = beam.length / sections;
  std::vector<Trip> mass;
  std::vector<std::vector<Trip>> stiff(static_cast<std::size_t>(sections)), slopes(static_cast<std::size_t>(sections));
  auto scatter = [&](std::vector<Trip>& out, int e, const hermite::Mat4& k) {
    for (int a = 0; a < 4; ++a) {
      const int ra = fe.full_to_reduced[static_cast<std::size_t>(2 * e + a)];
      if (ra < 0) continue;
      for (int b = 0; b < 4; ++b) {
        const int rb = fe.full_to_reduced[static_cast<std::size_t>(2 * e + b)];
        if (rb >= 0) out.emplace_back(ra, rb, k(a, b));
      }
    }
  };
  for (int e = 0; e < elements; ++e) {
    scatter(mass, e, hermite::mass(h, 0.0, h));
    // Split the element at section boundaries so jumps of EI (and of d = 2ζ√(ρA EI)) are
    // integrated exactly.
    const double sa = e * h, sb = (e + 1) * h;
    int s = std::min(sections - 1, static_cast<int>(std::floor(sa / hs + 1e-12)));
    double lo = sa;
    while (lo < sb - 1e-12 * h) {
      const double hi = std::min(sb, (s + 1) * hs);
      if (hi > lo + 1e-12 * h) {
        scatter(stiff[static_cast<std::size_t>(s)], e, hermite::stiffness(h, lo - sa, hi - sa));
        scatter(slopes[static_cast<std::size_t>(s)], e, hermite::slope_product(h, lo - sa, hi - sa));
      }
      lo = hi;
      s = std::min(sections - 1, s + 1);
      if (hi >= sb) break;
    }
  }
  m.mass.push_back({sparse_of(n, mass), fe.coef_rho_A()});
  // K = Σ EI_k K_k; D = Σ d_k G_k (Chen–Russell) + c_kv Σ K_k (Kelvin–Voigt, one coefficient for
  // the whole beam: the unit-EI stiffness summed over the sections). docs/theory.md §2.2.
  SparseMatrix Kunit(n, n);
  for (int s = 0; s < sections; ++s) {
    const SparseMatrix Ks = sparse_of(n, stiff[static_cast<std::size_t>(s)]);
    m.stiffness.push_back({Ks, fe.coef_EI(s)});
    Kunit += Ks;
  }
  for (int s = 0; s < sections; ++s) m.damping.push_back({sparse_of(n, slopes[static_cast<std::size_t>(s)]), fe.coef_chen_russell(s)});
  m.damping.push_back({Kunit, fe.coef_kelvin_voigt()});
  if (beam.tip_mass > 0.0 || beam.tip_inertia > 0.0) {
    std::vector<Trip> tip;
    const int rw = fe.full_to_reduced[static_cast<std::size_t>(2 * elements)];
    const int rt = fe.full_to_reduced[static_cast<std::size_t>(2 * elements + 1)];
    if (rw >= 0 && beam.tip_mass > 0.0) tip.emplace_back(rw, rw, beam.tip_mass);
    if (rt >= 0 && beam.tip_inertia > 0.0) tip.emplace_back(rt, rt, beam.tip_inertia);
    if (!tip.empty()) m.mass.push_back({sparse_of(n, tip), -1});
  }
}

// A point element at s: m N Nᵀ and J N′N′ᵀ in M, k_w N Nᵀ and k_θ N′N′ᵀ in K, c_w N Nᵀ and
// c_θ N′N′ᵀ in D, N (N′) the displacement (slope) row at s (docs/theory.md §2.5). Each row lies
// on one element's DOFs, so the operators keep the mesh's pattern. A lumped attachment with DOF
// a (unit row e_a): m_l e_a e_aᵀ in M, k_l (N − e_a)(N − e_a)ᵀ in K and c_l the same in D, the
// ground spring k_g e_a e_aᵀ in K (its row joins the banded solver's border).
void point_element_terms(BeamFE& fe, const io::BeamSpec& beam, int n) {
  StructuralModel& m = fe.model;
  const std::map<std::string, int>& lumped_dof = fe.lumped_dof;
  for (std::size_t k = 0; k < fe.points.size(); ++k) {
    const auto& p = fe.points[k];
    const std::string element = p.name.substr(p.name.find('.') + 1, p.name.rfind('.') - p.name.find('.') - 1);
    if (!(p.location >= 0.0 && p.location <= beam.length))
      throw std::logic_error("build_beam: " + p.name + " is not on the beam (io::validate_scenario refuses it)");
    const bool slope = p.field == "inertia" || p.field == "k_theta" || p.field == "c_theta";
    const bool lumped = p.field.rfind("lumped_", 0) == 0;
    Eigen::RowVectorXd row = slope ? fe.rotation_row(p.location) : fe.displacement_row(p.location);
    if (lumped) {
      Eigen::RowVectorXd unit = Eigen::RowVectorXd::Zero(n);
      unit[lumped_dof.at(element)] = 1.0;
      row = p.field == "lumped_k" || p.field == "lumped_c" ? Eigen::RowVectorXd(row - unit) : unit;
    }
    std::vector<Trip> t;
    for (int a = 0; a < n; ++a)
      if (row[a] != 0.0)
        for (int b = 0; b < n; ++b)
          if (row[b] != 0.0) t.emplace_back(a, b, row[a] * row[b]);
    OperatorTerm term{sparse_of(n, t), fe.coef_point(static_cast<int>(k))};
    if (p.field == "mass" || p.field == "inertia" || p.field == "lumped_mass") m.mass.push_back(std::move(term));
    else if (p.field == "k_w" || p.field == "k_theta" || p.field == "lumped_k" || p.field == "lumped_k_ground") m.stiffness.push_back(std::move(term));
    else m.damping.push_back(std::move(term));
  }

}

}  // namespace

BeamFE build_beam(const io::BeamSpec& beam, int elements, int sections, const std::vector<io::InputSpec>& inputs,
                  const std::vector<io::SensorSpec>& sensors) {
  if (elements < 1) throw std::logic_error("build_beam: " + std::to_string(elements) + " elements");
  if (sections < 1) sections = static_cast<int>(beam.EI.size());
  BeamFE fe;
  fe.length = beam.length;
  fe.elements = elements;
  fe.sections = sections;
  const int n = beam_dofs(fe, beam);
  beam_coefficients(fe, beam, n);
  beam_operators(fe, beam, n);
  point_element_terms(fe, beam, n);
  add_beam_inputs(fe, beam, inputs);
  add_beam_sensors(fe, beam, sensors);
  return fe;
}

double point_value(const BeamFE::PointQuantity& p, const io::BeamSpec& beam) {
  for (const bool supports : {true, false})
    for (const auto& e : supports ? beam.supports : beam.attachments)
      for (const auto& [key, member] : io::point_element_fields())
        if (io::point_element_parameter(supports ? "supports" : "attachments", e, key) == p.name) return e.*member;
  return std::nan("");
}

VectorXd beam_coefficients(const BeamFE& fe, double rho_A, const std::vector<double>& EI, double zeta, double c_kv) {
  VectorXd c(fe.model.ncoef);
  c[fe.coef_rho_A()] = rho_A;
  for (int s = 0; s < fe.sections; ++s) {
    const double ei = EI.size() == 1 ? EI[0] : EI.at(static_cast<std::size_t>(s));
    c[fe.coef_EI(s)] = ei;
    c[fe.coef_chen_russell(s)] = 2.0 * zeta * std::sqrt(rho_A * ei);
  }
  c[fe.coef_kelvin_voigt()] = c_kv;
  for (std::size_t k = 0; k < fe.points.size(); ++k) c[fe.coef_point(static_cast<int>(k))] = fe.points[k].value;
  return c;
}

// ---------------------------------------------------------------------------------------------

namespace {
std::vector<double> expand_sections(const std::vector<double>& EI, int sections) {
  std::vector<double> out(static_cast<std::size_t>(sections));
  const int n = static_cast<int>(EI.size());
  for (int s = 0; s < sections; ++s) {
    // value at the centre of model section s, read from the scenario's own sections
    const double x = (s + 0.5) / sections;
    out[static_cast<std::size_t>(s)] = EI[static_cast<std::size_t>(std::min(n - 1, static_cast<int>(x * n)))];
  }
  return out;
}
// True sectional values are well defined when every model section lies inside one scenario section.
bool sections_nest(int scenario_sections, int model_sections) {
  return scenario_sections == 1 || model_sections % scenario_sections == 0;
}
}  // namespace

ParameterSpace beam_parameter_space(const BeamFE& fe, const io::BeamSpec& beam) {
  const int N = fe.sections;
  ParameterSpace sp;
  sp.structure = "beam";
  const std::vector<double> EI = expand_sections(beam.EI, N);
  const bool nest = sections_nest(static_cast<int>(beam.EI.size()), N);
  sp.quantities.push_back("rho_A");
  sp.value.push_back(beam.rho_A);
  sp.true_value.push_back(true);
  ParameterSpace::Group ei{"EI", {}, false};
  for (int k = 0; k < N; ++k) {
    sp.quantities.push_back("EI_" + std::to_string(k + 1));
    sp.value.push_back(EI[static_cast<std::size_t>(k)]);
    sp.true_value.push_back(nest);
    ei.members.push_back(1 + k);
  }
  sp.quantities.push_back("zeta");
  sp.value.push_back(beam.zeta);
  sp.true_value.push_back(true);
  sp.quantities.push_back("c_kv");
  sp.value.push_back(beam.c_kv);
  sp.true_value.push_back(true);
  // The point elements' values in `beam` (a truth's may differ from the mesh's scenario; a
  // quantity it lacks has no true value).
  for (const auto& p : fe.points) {
    const double v = point_value(p, beam);
    sp.quantities.push_back(p.name);
    sp.value.push_back(std::isnan(v) ? p.value : v);
    sp.true_value.push_back(!std::isnan(v));
  }
  sp.groups.push_back(ei);
  sp.rho_A = 0;
  sp.q3_quantity = N + 2;
  sp.has_q3 = true;
  if (N > 1) sp.paper_requirement = "needs a uniform beam (one EI section), not " + std::to_string(N) + " sections";
  sp.ncoef = fe.model.ncoef;
  // φ = [ρA, EI_1..EI_N, ζ, c_kv] → c = [ρA, EI_1..EI_N, d_1..d_N, c_kv], d_k = 2ζ√(ρA EI_k)
  // (Chen–Russell), c_kv as is (Kelvin–Voigt); docs/theory.md §2.2.
  // The point elements' quantities follow c_kv in both.
  const int P = static_cast<int>(fe.points.size());
  sp.coefficients = [N, P](const std::vector<ParameterSpace::Cd>& f) {
    std::vector<ParameterSpace::Cd> c(static_cast<std::size_t>(2 + 2 * N + P));
    for (int k = 0; k < P; ++k) c[static_cast<std::size_t>(2 + 2 * N + k)] = f[static_cast<std::size_t>(N + 3 + k)];
    c[0] = f[0];
    for (int k = 0; k < N; ++k) {
      c[static_cast<std::size_t>(1 + k)] = f[static_cast<std::size_t>(1 + k)];
      c[static_cast<std::size_t>(1 + N + k)] = 2.0 * f[static_cast<std::size_t>(N + 1)] * std::sqrt(f[0] * f[static_cast<std::size_t>(1 + k)]);
    }
    c[static_cast<std::size_t>(1 + 2 * N)] = f[static_cast<std::size_t>(N + 2)];
    return c;
  };
  return sp;
}

namespace {

class BeamStructure final : public FEStructure {
public:
  BeamStructure(const io::Scenario& sc, int elements)
      : fe_(build_beam(sc.beam, elements, sc.identification.sections, sc.inputs, sc.sensors)) {}
  const StructuralModel& model() const override { return fe_.model; }
  int elements() const override { return fe_.elements; }
  double length() const override { return fe_.length; }
  ParameterSpace parameter_space(const io::Scenario& sc) const override { return beam_parameter_space(fe_, sc.beam); }
  VectorXd coefficients(const io::Scenario& sc) const override {
    VectorXd c = beam_coefficients(fe_, sc.beam.rho_A, sc.beam.EI, sc.beam.zeta, sc.beam.c_kv);
    for (std::size_t k = 0; k < fe_.points.size(); ++k)  // the point elements' values in sc (its truth's may differ)
      if (const double v = point_value(fe_.points[k], sc.beam); !std::isnan(v)) c[fe_.coef_point(static_cast<int>(k))] = v;
    return c;
  }
  std::vector<double> exact_hz(const io::Scenario& sc, int count, std::string& what) const override {
    return analytic::beam_hz(sc.beam, count, what);
  }

private:
  BeamFE fe_;
};

}  // namespace

std::unique_ptr<FEStructure> make_beam_structure(const io::Scenario& sc, int elements) {
  return std::make_unique<BeamStructure>(sc, elements);
}

}  // namespace scoleid::identify
