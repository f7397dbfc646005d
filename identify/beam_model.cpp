#include "scoleid/identify/beam_model.h"

#include <cmath>
#include <complex>

#include "scoleid/identify/hermite_beam.h"
#include "scoleid/io/error.h"

namespace scoleid::identify {

using io::EndCondition;
using io::fail_field;
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

Eigen::RowVectorXd field_row(const BeamFE& fe, double s, bool rotation) {
  Eigen::RowVectorXd row = Eigen::RowVectorXd::Zero(fe.model.ndof);
  double xi = 0.0;
  const double h = fe.length / fe.elements;
  const int e = element_of(s, fe.length, fe.elements, xi);
  const hermite::Vec4 n = rotation ? hermite::slope(xi, h) : hermite::shape(xi, h);
  for (int a = 0; a < 4; ++a) {
    const int r = fe.full_to_reduced[static_cast<std::size_t>(2 * e + a)];
    if (r >= 0) row[r] += n[a];
  }
  return row;
}

}  // namespace

Eigen::RowVectorXd BeamFE::displacement_row(double s) const { return field_row(*this, s, false); }
Eigen::RowVectorXd BeamFE::rotation_row(double s) const { return field_row(*this, s, true); }

BeamFE build_beam(const io::BeamSpec& beam, int elements, int sections, const std::vector<io::InputSpec>& inputs,
                  const std::vector<io::SensorSpec>& sensors, const std::string& source) {
  if (elements < 1) fail_field(source, "identification.elements", "must be >= 1", std::to_string(elements));
  if (sections < 1) sections = static_cast<int>(beam.EI.size());
  BeamFE fe;
  fe.length = beam.length;
  fe.elements = elements;
  fe.sections = sections;
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
  if (n == 0) fail_field(source, "beam", "leaves no free degree of freedom", std::to_string(elements) + " elements");

  StructuralModel& m = fe.model;
  m.ndof = n;
  m.ncoef = 1 + 2 * sections;
  m.coefficient_names.push_back("rho_A");
  for (int s = 0; s < sections; ++s) m.coefficient_names.push_back("EI_" + std::to_string(s + 1));
  for (int s = 0; s < sections; ++s) m.coefficient_names.push_back("c_" + std::to_string(s + 1));
  m.dof_group.resize(static_cast<std::size_t>(n));
  for (int i = 0; i < nfull; ++i) {
    const int r = fe.full_to_reduced[static_cast<std::size_t>(i)];
    if (r >= 0) m.dof_group[static_cast<std::size_t>(r)] = i % 2;  // 0: w, 1: θ
  }

  using Trip = Eigen::Triplet<double>;
  const double h = beam.length / elements;
  const double hs = beam.length / sections;
  std::vector<Trip> mass;
  std::vector<std::vector<Trip>> stiff(static_cast<std::size_t>(sections));
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
    // Split the element at section boundaries so EI jumps are integrated exactly.
    const double sa = e * h, sb = (e + 1) * h;
    int s = std::min(sections - 1, static_cast<int>(std::floor(sa / hs + 1e-12)));
    double lo = sa;
    while (lo < sb - 1e-12 * h) {
      const double hi = std::min(sb, (s + 1) * hs);
      if (hi > lo + 1e-12 * h) scatter(stiff[static_cast<std::size_t>(s)], e, hermite::stiffness(h, lo - sa, hi - sa));
      lo = hi;
      s = std::min(sections - 1, s + 1);
      if (hi >= sb) break;
    }
  }
  auto to_sparse = [n](const std::vector<Trip>& t) {
    SparseMatrix A(n, n);
    A.setFromTriplets(t.begin(), t.end());
    A.makeCompressed();
    return A;
  };
  m.mass.push_back({to_sparse(mass), fe.coef_rho_A()});
  for (int s = 0; s < sections; ++s) {
    const SparseMatrix Ks = to_sparse(stiff[static_cast<std::size_t>(s)]);
    m.stiffness.push_back({Ks, fe.coef_EI(s)});
    m.damping.push_back({Ks, fe.coef_damping(s)});
  }
  if (beam.tip_mass > 0.0 || beam.tip_inertia > 0.0) {
    std::vector<Trip> tip;
    const int rw = fe.full_to_reduced[static_cast<std::size_t>(2 * elements)];
    const int rt = fe.full_to_reduced[static_cast<std::size_t>(2 * elements + 1)];
    if (rw >= 0 && beam.tip_mass > 0.0) tip.emplace_back(rw, rw, beam.tip_mass);
    if (rt >= 0 && beam.tip_inertia > 0.0) tip.emplace_back(rt, rt, beam.tip_inertia);
    if (!tip.empty()) m.mass.push_back({to_sparse(tip), -1});
  }

  for (std::size_t i = 0; i < inputs.size(); ++i) {
    const auto& in = inputs[i];
    const std::string f = "inputs[" + std::to_string(i) + "]";
    if (in.at != "beam") fail_field(source, f + ".at", "must be 'beam' for a beam structure", "'" + in.at + "'");
    if (!(in.location >= 0.0 && in.location <= beam.length))
      fail_field(source, f + ".location", "must lie on the beam [0, " + format_value(beam.length) + "]",
                 format_value(in.location));
    ModelInput mi;
    mi.name = in.name;
    mi.vector = (in.kind == "moment" ? fe.rotation_row(in.location) : fe.displacement_row(in.location)).transpose();
    m.inputs.push_back(std::move(mi));
  }
  for (std::size_t k = 0; k < sensors.size(); ++k) {
    const auto& se = sensors[k];
    const std::string f = "sensors[" + std::to_string(k) + "]";
    if (se.at != "beam") fail_field(source, f + ".at", "must be 'beam' for a beam structure", "'" + se.at + "'");
    if (se.kind != "displacement" && se.kind != "rotation")
      fail_field(source, f + ".kind", "is not supported by the beam identifier (displacement|rotation)",
                 "'" + se.kind + "'");
    if (!(se.location >= 0.0 && se.location <= beam.length))
      fail_field(source, f + ".location", "must lie on the beam [0, " + format_value(beam.length) + "]",
                 format_value(se.location));
    ModelSensor ms;
    ms.name = se.name;
    ms.kind = se.kind;
    ms.row = se.kind == "rotation" ? fe.rotation_row(se.location) : fe.displacement_row(se.location);
    m.sensors.push_back(std::move(ms));
  }
  return fe;
}

VectorXd beam_coefficients(const BeamFE& fe, double rho_A, const std::vector<double>& EI, double zeta) {
  VectorXd c(fe.model.ncoef);
  c[fe.coef_rho_A()] = rho_A;
  for (int s = 0; s < fe.sections; ++s) {
    const double ei = EI.size() == 1 ? EI[0] : EI.at(static_cast<std::size_t>(s));
    c[fe.coef_EI(s)] = ei;
    c[fe.coef_damping(s)] = 2.0 * zeta * std::sqrt(rho_A * ei);
  }
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

BeamParameterization::BeamParameterization(const BeamFE& fe, const io::BeamSpec& truth,
                                           const io::IdentificationSpec& id, const std::string& source)
    : sections_(fe.sections), ncoef_(fe.model.ncoef), paper_(id.parameterization == "paper") {
  names_ = id.estimate;
  if (names_.empty()) fail_field(source, "identification.estimate", "must name at least one parameter", "none");
  std::vector<std::string> allowed;
  if (paper_) {
    allowed = {"q1", "q2", "q3"};
  } else {
    allowed = {"rho_A", "EI", "zeta"};
    for (int s = 0; s < sections_; ++s) allowed.push_back("EI_" + std::to_string(s + 1));
  }
  for (std::size_t i = 0; i < names_.size(); ++i) {
    bool ok = false;
    for (const auto& a : allowed) ok = ok || a == names_[i];
    if (!ok) {
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : "|") + a;
      fail_field(source, "identification.estimate[" + std::to_string(i) + "]",
                 "must be one of " + list + " (" + id.parameterization + " parameterization)", "'" + names_[i] + "'");
    }
    for (std::size_t j = 0; j < i; ++j)
      if (names_[j] == names_[i])
        fail_field(source, "identification.estimate[" + std::to_string(i) + "]", "is listed twice", "'" + names_[i] + "'");
    if (!paper_ && names_[i] == "EI")
      for (const auto& o : names_)
        if (o.rfind("EI_", 0) == 0)
          fail_field(source, "identification.estimate", "cannot hold both EI and sectional EI_k", "'" + o + "'");
  }
  if (paper_ && sections_ > 1)
    fail_field(source, "identification.parameterization", "paper form needs a uniform beam (one EI section)",
               std::to_string(sections_) + " sections");
  for (const auto& [key, v] : id.initial) {
    bool ok = key == "rho_A" || key == "EI" || key == "zeta" || key == "q1" || key == "q2" || key == "q3";
    if (key.rfind("EI_", 0) == 0) {
      const int k = std::atoi(key.c_str() + 3);
      ok = k >= 1 && k <= sections_ && key == "EI_" + std::to_string(k);
    }
    if (!ok) fail_field(source, "identification.initial." + key, "is not a parameter of this beam", format_value(v));
  }

  // Physical starting state: the scenario's values, overridden by identification.initial.
  const auto get = [&](const std::string& k, double d) {
    const auto it = id.initial.find(k);
    return it == id.initial.end() ? d : it->second;
  };
  State<double> true_state{truth.rho_A, expand_sections(truth.EI, sections_), truth.zeta};
  start_ = true_state;
  start_.rho_A = get("rho_A", start_.rho_A);
  if (id.initial.count("EI")) std::fill(start_.EI.begin(), start_.EI.end(), id.initial.at("EI"));
  for (int s = 0; s < sections_; ++s) start_.EI[static_cast<std::size_t>(s)] = get("EI_" + std::to_string(s + 1), start_.EI[static_cast<std::size_t>(s)]);
  start_.zeta = get("zeta", start_.zeta);

  initial_ = parameters_of(start_);
  for (std::size_t i = 0; i < names_.size(); ++i) {
    const auto it = id.initial.find(names_[i]);
    if (it != id.initial.end()) initial_[static_cast<Eigen::Index>(i)] = it->second;
    if (!(initial_[static_cast<Eigen::Index>(i)] > 0.0))
      fail_field(source, "identification.initial." + names_[i], "must be > 0 (parameters are positive)",
                 format_value(initial_[static_cast<Eigen::Index>(i)]));
  }
  truth_ = parameters_of(true_state);
  if (!sections_nest(static_cast<int>(truth.EI.size()), sections_))
    for (std::size_t i = 0; i < names_.size(); ++i)
      if (names_[i].rfind("EI", 0) == 0) truth_[static_cast<Eigen::Index>(i)] = std::nan("");
}

VectorXd BeamParameterization::parameters_of(const State<double>& s) const {
  VectorXd q(static_cast<Eigen::Index>(names_.size()));
  double mean_EI = 0.0;
  for (double e : s.EI) mean_EI += e / static_cast<double>(s.EI.size());
  for (std::size_t i = 0; i < names_.size(); ++i) {
    const std::string& n = names_[i];
    double v = 0.0;
    if (n == "rho_A") v = s.rho_A;
    else if (n == "EI") v = mean_EI;
    else if (n == "zeta") v = s.zeta;
    else if (n == "q1") v = s.EI[0] / s.rho_A;
    else if (n == "q2") v = 1.0 / s.rho_A;
    else if (n == "q3") v = 2.0 * s.zeta * std::sqrt(s.EI[0] / s.rho_A);
    else v = s.EI[static_cast<std::size_t>(std::atoi(n.c_str() + 3) - 1)];
    q[static_cast<Eigen::Index>(i)] = v;
  }
  return q;
}

template <class T>
BeamParameterization::State<T> BeamParameterization::state(const std::vector<T>& q) const {
  State<T> s{T(start_.rho_A), {}, T(start_.zeta)};
  for (double e : start_.EI) s.EI.push_back(T(e));
  auto find = [&](const char* name) -> int {
    for (std::size_t i = 0; i < names_.size(); ++i)
      if (names_[i] == name) return static_cast<int>(i);
    return -1;
  };
  if (paper_) {
    // Paper form: the equation divided by ρA. Unestimated q's keep their starting values.
    const int i1 = find("q1"), i2 = find("q2"), i3 = find("q3");
    const T q1 = i1 >= 0 ? q[static_cast<std::size_t>(i1)] : T(start_.EI[0] / start_.rho_A);
    const T q2 = i2 >= 0 ? q[static_cast<std::size_t>(i2)] : T(1.0 / start_.rho_A);
    const T q3 = i3 >= 0 ? q[static_cast<std::size_t>(i3)] : T(2.0 * start_.zeta * std::sqrt(start_.EI[0] / start_.rho_A));
    s.rho_A = T(1.0) / q2;
    s.EI[0] = q1 / q2;
    s.zeta = q3 / (T(2.0) * std::sqrt(q1));
    return s;
  }
  for (std::size_t i = 0; i < names_.size(); ++i) {
    const std::string& n = names_[i];
    if (n == "rho_A") s.rho_A = q[i];
    else if (n == "zeta") s.zeta = q[i];
    else if (n == "EI") for (auto& e : s.EI) e = q[i];
    else s.EI[static_cast<std::size_t>(std::atoi(n.c_str() + 3) - 1)] = q[i];
  }
  return s;
}

void BeamParameterization::coefficients(const VectorXd& q, VectorXd& c, MatrixXd& dcdq) const {
  using C = std::complex<double>;
  const int P = static_cast<int>(names_.size());
  auto coef = [&](const std::vector<C>& qc, std::vector<C>& out) {
    const State<C> s = state(qc);
    out.assign(static_cast<std::size_t>(ncoef_), C(0.0));
    out[0] = s.rho_A;
    for (int k = 0; k < sections_; ++k) {
      out[static_cast<std::size_t>(1 + k)] = s.EI[static_cast<std::size_t>(k)];
      out[static_cast<std::size_t>(1 + sections_ + k)] = C(2.0) * s.zeta * std::sqrt(s.rho_A * s.EI[static_cast<std::size_t>(k)]);
    }
  };
  std::vector<C> qc(static_cast<std::size_t>(P)), out;
  for (int i = 0; i < P; ++i) qc[static_cast<std::size_t>(i)] = C(q[i], 0.0);
  coef(qc, out);
  c.resize(ncoef_);
  for (int j = 0; j < ncoef_; ++j) c[j] = out[static_cast<std::size_t>(j)].real();
  // Complex-step derivative: exact to rounding, no subtractive cancellation.
  dcdq.setZero(ncoef_, P);
  for (int i = 0; i < P; ++i) {
    const double h = 1e-30 * std::max(1.0, std::abs(q[i]));
    qc[static_cast<std::size_t>(i)] = C(q[i], h);
    coef(qc, out);
    for (int j = 0; j < ncoef_; ++j) dcdq(j, i) = out[static_cast<std::size_t>(j)].imag() / h;
    qc[static_cast<std::size_t>(i)] = C(q[i], 0.0);
  }
}

std::map<std::string, double> BeamParameterization::physical(const VectorXd& q) const {
  std::vector<double> qv(q.data(), q.data() + q.size());
  const State<double> s = state(qv);
  std::map<std::string, double> out{{"rho_A", s.rho_A}, {"zeta", s.zeta}};
  if (sections_ == 1) {
    out["EI"] = s.EI[0];
  } else {
    for (int k = 0; k < sections_; ++k) out["EI_" + std::to_string(k + 1)] = s.EI[static_cast<std::size_t>(k)];
  }
  return out;
}

template BeamParameterization::State<double> BeamParameterization::state(const std::vector<double>&) const;

}  // namespace scoleid::identify
