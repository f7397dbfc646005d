#pragma once
// Named parameters over a structure's physical quantities (docs/theory.md §2.3, §3): the one
// implementation of Parameterization; a structure only describes its quantities (ParameterSpace).
//
// φ = the structure's physical quantities in table order (ρA, EI per section or plane, ...), with
// the scenario's values; c(φ) its model coefficients (structural_model.h). A parameter is
//   - a quantity by name (rho_A, EI_2, GJ, m_reflector, ...),
//   - a group name that sets several quantities to one value (EI: every section, both planes),
//   - or, in the paper's form (the equation divided by ρA), q1 = EI/ρA, q2 = 1/ρA and, where the
//     structure has it, q3 = c_kv/ρA (EI the group, c_kv the Kelvin–Voigt coefficient; c_kv = q3/q2).
//     Beside them the paper form estimates by name any quantity or group they do not stand for
//     (ζ, ρI_ψ, the masses): identification.estimate [q1, q2, zeta].
// Quantities not estimated keep their starting values: the scenario's, overridden by
// identification.initial (keys: quantity, group and q names). ∂c/∂q by complex step: exact to
// rounding, no step-size choice.
#include <complex>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "scoleid/identify/inverse/parameterization.h"
#include "scoleid/io/scenario.h"

namespace scoleid::identify {

struct ParameterSpace {
  using Cd = std::complex<double>;
  std::string structure;                 // in messages: "beam", "SCOLE"
  std::vector<std::string> quantities;   // φ names
  std::vector<double> value;             // φ at the scenario's values
  std::vector<bool> true_value;          // whether value[i] is a true value (else reported NaN)
  struct Group {
    std::string name;
    std::vector<int> members;
    bool report_when_equal = true;       // physical() shows the group name when all members agree
  };
  std::vector<Group> groups;
  // Paper form: the quantities behind q1, q2 (, q3): ρA, the EI group and the quantity X with
  // q3 = X/ρA (the beam's Kelvin–Voigt coefficient c_kv); q3 only if has_q3.
  int rho_A = -1, q3_quantity = -1;
  std::string EI_group = "EI";
  bool has_q3 = false;
  std::string paper_requirement;          // non-empty: the paper form is refused with this reason
  int ncoef = 0;
  std::function<std::vector<Cd>(const std::vector<Cd>& phi)> coefficients;
};

// What a parameterization cannot take from identification.estimate / .initial / .parameterization:
// the field, the requirement and the value, as io::fail_field writes them (the door raises it:
// identify::check_parameters).
struct ParameterRefusal {
  std::string field, what, value;
};

class PhysicalParameterization final : public Parameterization {
public:
  using Cd = std::complex<double>;
  // The names resolved against the space; the first thing it cannot take is kept as refusal()
  // (then only refusal() and truth() — when the names resolved — are meaningful).
  PhysicalParameterization(ParameterSpace space, const io::IdentificationSpec& id);
  const std::optional<ParameterRefusal>& refusal() const { return refusal_; }
  const std::vector<std::string>& names() const override { return names_; }
  void coefficients(const VectorXd& q, VectorXd& c, MatrixXd& dcdq) const override;
  std::map<std::string, double> physical(const VectorXd& q) const override;
  VectorXd initial() const override { return initial_; }
  VectorXd truth() const override { return truth_; }
  bool paper_form() const override { return paper_; }

private:
  void resolve(const io::IdentificationSpec& id);
  std::vector<std::string> allowed_names(const std::vector<std::string>& paper_names) const;
  std::vector<double> starting_values(const std::map<std::string, double>& initial) const;
  void refuse(std::string field, std::string what, std::string value);
  const ParameterSpace::Group* group(const std::string& name) const;
  int quantity(const std::string& name) const;
  // φ for parameter values q (complex for the complex step), from the starting φ.
  std::vector<Cd> phi(const std::vector<Cd>& q) const;
  // Parameter values of a φ (NaN where a group's members differ or a value is not a true one).
  VectorXd parameters_of(const std::vector<double>& phi, const std::vector<bool>* defined) const;

  ParameterSpace space_;
  bool paper_ = false;
  std::vector<std::string> names_;
  std::vector<double> start_;
  VectorXd initial_, truth_;
  std::optional<ParameterRefusal> refusal_;
};

}  // namespace scoleid::identify
