#pragma once
// Finite-element model of the Euler–Bernoulli beam of docs/theory.md §2, in the form of
// structural_model.h:
//
//   ρA w_tt + (c(s) w_sst)_ss + (EI(s) w_ss)_ss = Σ_i f_i(t) δ(s − s_i)   (or δ′ for moments)
//   c(s) = 2 ζ sqrt(ρA EI(s))   (Kelvin–Voigt; ζ is the first-mode damping ratio of a uniform beam)
//
// Hermite cubic elements on a uniform mesh; EI piecewise constant on N equal sections;
// ends pinned (w = 0), clamped (w = w_s = 0) or free (natural conditions); optional rigid tip
// mass and rotary inertia at s = L. Constrained DOFs are eliminated.
// Coefficients: c = [ρA, EI_1..EI_N, c_1..c_N]. Loads and sensors anywhere on the beam, through
// the shape functions (a sensor between nodes reads the interpolated field).
#include <string>
#include <vector>

#include "scoleid/identify/parameterization.h"
#include "scoleid/identify/structural_model.h"
#include "scoleid/io/scenario.h"

namespace scoleid::identify {

struct BeamFE {
  StructuralModel model;
  double length = 0.0;
  int elements = 0;
  int sections = 0;
  std::vector<int> full_to_reduced;  // 2 per node: (w, θ); -1 where constrained

  int coef_rho_A() const { return 0; }
  int coef_EI(int s) const { return 1 + s; }
  int coef_damping(int s) const { return 1 + sections + s; }

  // Rows acting on the reduced DOF vector.
  Eigen::RowVectorXd displacement_row(double s) const;
  Eigen::RowVectorXd rotation_row(double s) const;
};

// `source` names the scenario in error messages. Inputs of kind force/moment at `location`;
// sensors of kind displacement/rotation (others are rejected with InputError).
BeamFE build_beam(const io::BeamSpec& beam, int elements, int sections, const std::vector<io::InputSpec>& inputs,
                  const std::vector<io::SensorSpec>& sensors, const std::string& source);

// Coefficients c for a physical state (ρA, EI per section, ζ).
VectorXd beam_coefficients(const BeamFE& fe, double rho_A, const std::vector<double>& EI, double zeta);

// Named parameters for a beam (see io::IdentificationSpec):
//   physical: rho_A, EI (all sections), EI_k (k = 1..N), zeta
//   paper:    q1 = EI/ρA, q2 = 1/ρA, q3 = 2ζ sqrt(EI/ρA)  (the beam equation divided by ρA)
// Quantities not estimated keep their starting values: the scenario's values overridden by
// identification.initial.
class BeamParameterization final : public Parameterization {
public:
  BeamParameterization(const BeamFE& fe, const io::BeamSpec& truth, const io::IdentificationSpec& id,
                       const std::string& source);
  const std::vector<std::string>& names() const override { return names_; }
  void coefficients(const VectorXd& q, VectorXd& c, MatrixXd& dcdq) const override;
  std::map<std::string, double> physical(const VectorXd& q) const override;
  VectorXd initial() const override { return initial_; }
  VectorXd truth() const override { return truth_; }
  bool paper_form() const override { return paper_; }

  template <class T>
  struct State {
    T rho_A;
    std::vector<T> EI;
    T zeta;
  };
  template <class T>
  State<T> state(const std::vector<T>& q) const;

private:
  VectorXd parameters_of(const State<double>& s) const;

  int sections_ = 1;
  int ncoef_ = 0;
  bool paper_ = false;
  std::vector<std::string> names_;
  State<double> start_;  // physical starting state (fixed values for what is not estimated)
  VectorXd initial_, truth_;
};

}  // namespace scoleid::identify
