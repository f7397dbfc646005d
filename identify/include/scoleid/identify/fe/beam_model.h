#pragma once
// Finite-element model of the Euler–Bernoulli beam of docs/theory.md §2, in the form of
// structural_model.h:
//
//   ρA w_tt − (d(s) w_st)_s + (c_kv w_sst)_ss + (EI(s) w_ss)_ss = Σ_i f_i(t) δ(s − s_i)   (or δ′ for moments)
//
//   d(s) = 2 ζ sqrt(ρA EI(s))   square-root (Chen–Russell) damping, ζ dimensionless: every mode of a
//                               uniform pinned–pinned beam has damping ratio exactly ζ
//                               (docs/theory.md §2.2); d follows EI section by section.
//   c_kv                        Kelvin–Voigt (strain-rate) coefficient [EI × time], one value for
//                               the whole beam, also when EI has sections (docs/theory.md §2.2).
//
// Hermite cubic elements on a uniform mesh; EI piecewise constant on N equal sections;
// ends pinned (w = 0), clamped (w = w_s = 0) or free (natural conditions); optional rigid tip
// mass and rotary inertia at s = L; point elements (supports, attachments: masses, rotary
// inertias, springs and dashpots to ground) at any station. Constrained DOFs are eliminated.
// Coefficients: c = [ρA, EI_1..EI_N, d_1..d_N, c_kv, the point elements' quantities]. Operators: M = ρA M_1 (+ tip body),
// K = Σ_k EI_k K_k, D = Σ_k d_k G_k + c_kv Σ_k K_k, with K_k = ∫_{section k} N″N″ᵀ ds and
// G_k = ∫_{section k} N′N′ᵀ ds (hermite_beam.h). Loads and sensors anywhere on the beam, through
// the shape functions (a sensor between nodes reads the interpolated field).
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "scoleid/identify/inverse/physical_parameterization.h"
#include "scoleid/identify/fe/structural_model.h"
#include "scoleid/identify/fe/structure.h"
#include "scoleid/io/scenario.h"

namespace scoleid::identify {

struct BeamFE {
  StructuralModel model;
  double length = 0.0;
  int elements = 0;
  int sections = 0;
  std::vector<int> full_to_reduced;  // 2 per node: (w, θ); -1 where constrained
  std::map<std::string, int> lumped_dof;  // a lumped attachment's own DOF, by the attachment's name
  // The point elements' quantities (supports and attachments, docs/theory.md §2.5), each > 0 and
  // one coefficient of its own after c_kv: its parameter name, station, field and value.
  struct PointQuantity {
    std::string name;
    double location = 0.0;
    std::string field;  // mass, inertia, k_w, k_theta, c_w, c_theta
    double value = 0.0;
  };
  std::vector<PointQuantity> points;

  int coef_rho_A() const { return 0; }
  int coef_EI(int s) const { return 1 + s; }
  int coef_chen_russell(int s) const { return 1 + sections + s; }  // d_s
  int coef_kelvin_voigt() const { return 1 + 2 * sections; }        // c_kv
  int coef_point(int k) const { return 2 + 2 * sections + k; }      // points[k]

  // Rows acting on the reduced DOF vector.
  Eigen::RowVectorXd displacement_row(double s) const;
  Eigen::RowVectorXd rotation_row(double s) const;
  Eigen::RowVectorXd curvature_row(double s) const;  // w_ss(s) (a strain gauge reads −offset times it)
};

// Inputs of kind force/moment at `location`; sensors of kind displacement/rotation (rows on u),
// velocity (u̇), acceleration (ü), strain and relative displacement. The inputs and sensors are a
// validated scenario's (io::validate_scenario: on the beam, of kinds it reads); anything else is a
// std::logic_error.
BeamFE build_beam(const io::BeamSpec& beam, int elements, int sections, const std::vector<io::InputSpec>& inputs,
                  const std::vector<io::SensorSpec>& sensors);

// A point quantity's value in `beam` (found by its parameter name), or NaN if `beam` lacks it.
double point_value(const BeamFE::PointQuantity& p, const io::BeamSpec& beam);

// Coefficients c for a physical state (ρA, EI per section, ζ, c_kv); EI holds one value or one
// per model section.
VectorXd beam_coefficients(const BeamFE& fe, double rho_A, const std::vector<double>& EI, double zeta, double c_kv = 0.0);

// The beam's parameter space (physical_parameterization.h): φ = [ρA, EI_1..EI_N (the model's N
// sections), ζ, c_kv, the point elements' quantities (supports.left.k_theta, attachments.clamp.mass)], the group EI (every section), the paper form q1 = EI/ρA, q2 = 1/ρA,
// q3 = c_kv/ρA (uniform beams only; ζ is held). φ's values: the scenario's beam (sections expanded
// to the model's; a model section's true EI is known when it lies inside one scenario section).
ParameterSpace beam_parameter_space(const BeamFE& fe, const io::BeamSpec& beam);

// The identifier's view of a beam scenario (fe/structure.h); make_structure's registry row.
std::unique_ptr<FEStructure> make_beam_structure(const io::Scenario& sc, int elements);

}  // namespace scoleid::identify
