#include "scoleid/identify/inverse/physical_parameterization.h"

#include <algorithm>
#include <cmath>

#include "scoleid/io/error.h"

namespace scoleid::identify {

using io::format_value;

namespace {
std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : "|") + x;
  return s;
}
}  // namespace

const ParameterSpace::Group* PhysicalParameterization::group(const std::string& name) const {
  for (const auto& g : space_.groups)
    if (g.name == name) return &g;
  return nullptr;
}

int PhysicalParameterization::quantity(const std::string& name) const {
  const auto it = std::find(space_.quantities.begin(), space_.quantities.end(), name);
  return it == space_.quantities.end() ? -1 : static_cast<int>(it - space_.quantities.begin());
}

PhysicalParameterization::PhysicalParameterization(ParameterSpace space, const io::IdentificationSpec& id)
    : space_(std::move(space)), paper_(id.parameterization == "paper") {
  resolve(id);
}

void PhysicalParameterization::refuse(std::string field, std::string what, std::string value) {
  refusal_ = ParameterRefusal{std::move(field), std::move(what), std::move(value)};
}

// The names identification.estimate may hold: q1, q2 (, q3) and what they do not stand for in the
// paper form (ζ, ρI_ψ, the masses, ...); every group and quantity in the physical one.
std::vector<std::string> PhysicalParameterization::allowed_names(const std::vector<std::string>& paper_names) const {
  std::vector<std::string> allowed;
  if (paper_) {
    // q1, q2 (, q3) and any quantity or group they do not stand for (ζ, ρI_ψ, the masses, ...).
    allowed = paper_names;
    std::vector<bool> taken(space_.quantities.size(), false);
    if (space_.rho_A >= 0) taken[static_cast<std::size_t>(space_.rho_A)] = true;
    if (space_.q3_quantity >= 0) taken[static_cast<std::size_t>(space_.q3_quantity)] = true;
    if (const auto* ei = group(space_.EI_group))
      for (int m : ei->members) taken[static_cast<std::size_t>(m)] = true;
    for (const auto& g : space_.groups) {
      bool free = true;
      for (int m : g.members) free = free && !taken[static_cast<std::size_t>(m)];
      if (free) allowed.push_back(g.name);
    }
    for (std::size_t k = 0; k < space_.quantities.size(); ++k)
      if (!taken[k]) allowed.push_back(space_.quantities[k]);
  } else {
    for (const auto& g : space_.groups) allowed.push_back(g.name);
    allowed.insert(allowed.end(), space_.quantities.begin(), space_.quantities.end());
  }
  return allowed;
}

// Starting φ: the scenario's values, overridden by identification.initial — groups first, then
// single quantities, then the paper's q2 (ρA), q1 (EI = q1 ρA) and q3 (X = q3 ρA).
std::vector<double> PhysicalParameterization::starting_values(const std::map<std::string, double>& ini) const {
  std::vector<double> start = space_.value;
  for (const auto& g : space_.groups)
    if (ini.count(g.name))
      for (int m : g.members) start[static_cast<std::size_t>(m)] = ini.at(g.name);
  for (std::size_t k = 0; k < space_.quantities.size(); ++k)
    if (ini.count(space_.quantities[k])) start[k] = ini.at(space_.quantities[k]);
  const auto* ei = group(space_.EI_group);
  if (space_.rho_A >= 0 && ini.count("q2")) start[static_cast<std::size_t>(space_.rho_A)] = 1.0 / ini.at("q2");
  if (ei && space_.rho_A >= 0 && ini.count("q1"))
    for (int m : ei->members) start[static_cast<std::size_t>(m)] = ini.at("q1") * start[static_cast<std::size_t>(space_.rho_A)];
  if (space_.rho_A >= 0 && space_.q3_quantity >= 0 && ini.count("q3"))
    start[static_cast<std::size_t>(space_.q3_quantity)] = ini.at("q3") * start[static_cast<std::size_t>(space_.rho_A)];
  return start;
}

void PhysicalParameterization::resolve(const io::IdentificationSpec& id) {
  names_ = id.estimate;
  if (names_.empty()) return refuse("identification.estimate", "must name at least one parameter", "none");
  if (paper_ && !space_.paper_requirement.empty())
    return refuse("identification.parameterization", space_.paper_requirement, "paper");
  std::vector<std::string> paper_names{"q1", "q2"};
  if (space_.has_q3) paper_names.push_back("q3");
  const std::vector<std::string> allowed = allowed_names(paper_names);
  for (std::size_t i = 0; i < names_.size(); ++i) {
    const std::string f = "identification.estimate[" + std::to_string(i) + "]";
    if (std::find(allowed.begin(), allowed.end(), names_[i]) == allowed.end())
      return refuse(f, "must be one of " + join(allowed) + " (" + id.parameterization + " parameterization of " +
                                space_.structure + ")",
                 "'" + names_[i] + "'");
    for (std::size_t j = 0; j < i; ++j)
      if (names_[j] == names_[i]) return refuse(f, "is listed twice", "'" + names_[i] + "'");
    if (const auto* g = group(names_[i]))
      for (const auto& o : names_)
        for (int m : g->members)
          if (o == space_.quantities[static_cast<std::size_t>(m)])
            return refuse("identification.estimate", "cannot hold both " + g->name + " and " + o, "'" + o + "'");
  }
  std::vector<std::string> keys = allowed;
  if (!paper_) keys.insert(keys.end(), paper_names.begin(), paper_names.end());
  else {
    for (const auto& g : space_.groups) keys.push_back(g.name);
    keys.insert(keys.end(), space_.quantities.begin(), space_.quantities.end());
  }
  for (const auto& [key, v] : id.initial)
    if (std::find(keys.begin(), keys.end(), key) == keys.end())
      return refuse("identification.initial." + key, "is not a parameter of this " + space_.structure, format_value(v));

  start_ = starting_values(id.initial);
  const auto& ini = id.initial;
  // A group estimated as one value must start as one value.
  for (const auto& n : names_) {
    const auto* g = group(n == "q1" ? space_.EI_group : n);
    if (!g) continue;
    for (int m : g->members)
      if (start_[static_cast<std::size_t>(m)] != start_[static_cast<std::size_t>(g->members[0])])
        return refuse("identification.estimate",
                   "estimates one " + g->name + " for " + std::to_string(g->members.size()) +
                       " quantities whose starting values differ (give identification.initial." + g->name +
                       ", or estimate them one by one)",
                   format_value(start_[static_cast<std::size_t>(g->members[0])]) + " and " +
                       format_value(start_[static_cast<std::size_t>(m)]));
  }
  initial_ = parameters_of(start_, nullptr);
  truth_ = parameters_of(space_.value, &space_.true_value);
  for (std::size_t i = 0; i < names_.size(); ++i) {
    // A starting value given for an estimated parameter is taken exactly.
    const auto it = ini.find(names_[i]);
    if (it != ini.end()) initial_[static_cast<Eigen::Index>(i)] = it->second;
    if (!(initial_[static_cast<Eigen::Index>(i)] > 0.0))
      return refuse("identification.initial." + names_[i], "must be > 0 (parameters are positive)",
                 format_value(initial_[static_cast<Eigen::Index>(i)]));
  }
}

VectorXd PhysicalParameterization::parameters_of(const std::vector<double>& phi, const std::vector<bool>* defined) const {
  const double nan = std::nan("");
  auto value = [&](int k) {
    return defined && !(*defined)[static_cast<std::size_t>(k)] ? nan : phi[static_cast<std::size_t>(k)];
  };
  auto group_value = [&](const ParameterSpace::Group& g) {
    const double v = value(g.members[0]);
    for (int m : g.members)
      if (!(value(m) == v)) return nan;
    return v;
  };
  VectorXd q(static_cast<Eigen::Index>(names_.size()));
  const auto* ei = group(space_.EI_group);
  for (std::size_t i = 0; i < names_.size(); ++i) {
    const std::string& n = names_[i];
    double v = nan;
    if (n == "q1" || n == "q2" || n == "q3") {
      const double rho = value(space_.rho_A), EI = ei ? group_value(*ei) : nan;
      if (n == "q1") v = EI / rho;
      else if (n == "q2") v = 1.0 / rho;
      else v = value(space_.q3_quantity) / rho;
    } else if (const auto* g = group(n)) {
      v = group_value(*g);
    } else {
      v = value(quantity(n));
    }
    q[static_cast<Eigen::Index>(i)] = v;
  }
  return q;
}

std::vector<PhysicalParameterization::Cd> PhysicalParameterization::phi(const std::vector<Cd>& q) const {
  std::vector<Cd> f(start_.begin(), start_.end());
  if (paper_) {
    // The equation divided by ρA; q's not estimated keep their starting values.
    const auto* ei = group(space_.EI_group);
    const auto rho0 = start_[static_cast<std::size_t>(space_.rho_A)], EI0 = start_[static_cast<std::size_t>(ei->members[0])];
    Cd q1 = EI0 / rho0, q2 = 1.0 / rho0, q3 = space_.has_q3 ? start_[static_cast<std::size_t>(space_.q3_quantity)] / rho0 : 0.0;
    for (std::size_t i = 0; i < names_.size(); ++i)
      if (names_[i] == "q1" || names_[i] == "q2" || names_[i] == "q3")
        (names_[i] == "q1" ? q1 : names_[i] == "q2" ? q2 : q3) = q[i];
    f[static_cast<std::size_t>(space_.rho_A)] = Cd(1.0) / q2;
    for (int m : ei->members) f[static_cast<std::size_t>(m)] = q1 / q2;
    if (space_.has_q3) f[static_cast<std::size_t>(space_.q3_quantity)] = q3 / q2;
  }
  // Quantities and groups estimated by name (in the paper form: those q1, q2, q3 do not stand for).
  for (std::size_t i = 0; i < names_.size(); ++i) {
    if (paper_ && (names_[i] == "q1" || names_[i] == "q2" || names_[i] == "q3")) continue;
    if (const auto* g = group(names_[i])) {
      for (int m : g->members) f[static_cast<std::size_t>(m)] = q[i];
    } else {
      f[static_cast<std::size_t>(quantity(names_[i]))] = q[i];
    }
  }
  return f;
}

void PhysicalParameterization::coefficients(const VectorXd& q, VectorXd& c, MatrixXd& dcdq) const {
  const int P = static_cast<int>(names_.size()), nc = space_.ncoef;
  std::vector<Cd> qc(static_cast<std::size_t>(P));
  for (int i = 0; i < P; ++i) qc[static_cast<std::size_t>(i)] = Cd(q[i], 0.0);
  std::vector<Cd> out = space_.coefficients(phi(qc));
  c.resize(nc);
  for (int j = 0; j < nc; ++j) c[j] = out[static_cast<std::size_t>(j)].real();
  dcdq.setZero(nc, P);
  for (int i = 0; i < P; ++i) {
    const double h = 1e-30 * std::max(1.0, std::abs(q[i]));
    qc[static_cast<std::size_t>(i)] = Cd(q[i], h);
    out = space_.coefficients(phi(qc));
    for (int j = 0; j < nc; ++j) dcdq(j, i) = out[static_cast<std::size_t>(j)].imag() / h;
    qc[static_cast<std::size_t>(i)] = Cd(q[i], 0.0);
  }
}

std::map<std::string, double> PhysicalParameterization::physical(const VectorXd& q) const {
  std::vector<Cd> qc(static_cast<std::size_t>(q.size()));
  for (Eigen::Index i = 0; i < q.size(); ++i) qc[static_cast<std::size_t>(i)] = q[i];
  const std::vector<Cd> f = phi(qc);
  std::map<std::string, double> out;
  std::vector<bool> shown(space_.quantities.size(), false);
  for (const auto& g : space_.groups) {
    bool equal = true;
    for (int m : g.members) equal = equal && f[static_cast<std::size_t>(m)] == f[static_cast<std::size_t>(g.members[0])];
    if (equal && (g.report_when_equal || g.members.size() == 1)) {
      out[g.name] = f[static_cast<std::size_t>(g.members[0])].real();
      for (int m : g.members) shown[static_cast<std::size_t>(m)] = true;
    }
  }
  for (std::size_t k = 0; k < space_.quantities.size(); ++k)
    if (!shown[k]) out[space_.quantities[k]] = f[k].real();
  return out;
}

}  // namespace scoleid::identify
