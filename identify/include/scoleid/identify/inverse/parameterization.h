#pragma once
// Named parameters q ↦ model coefficients c(q), with the Jacobian ∂c/∂q.
// Every parameter is positive (masses, stiffnesses, damping ratios and the paper's q's); the
// optimisers work on log q so positivity holds by construction.
#include <map>
#include <string>
#include <vector>

#include "scoleid/identify/fe/structural_model.h"

namespace scoleid::identify {

class Parameterization {
public:
  virtual ~Parameterization() = default;
  virtual const std::vector<std::string>& names() const = 0;
  virtual int size() const { return static_cast<int>(names().size()); }
  // c(q) and ∂c/∂q (ncoef × size()).
  virtual void coefficients(const VectorXd& q, VectorXd& c, MatrixXd& dcdq) const = 0;
  // The physical quantities these parameters stand for (for the report), e.g. rho_A, EI, zeta.
  virtual std::map<std::string, double> physical(const VectorXd& q) const = 0;
  virtual VectorXd initial() const = 0;
  // True values when the scenario knows them (empty otherwise).
  virtual VectorXd truth() const = 0;
  // The paper's form (the equation divided by ρA: q1 = EI/ρA, q2 = 1/ρA, ...), whose iteration
  // table also shows the physical ρA, EI, ζ.
  virtual bool paper_form() const { return false; }
};

}  // namespace scoleid::identify
