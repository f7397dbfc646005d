#pragma once
// The identified linear model as a plant for control design (docs/theory.md §10.2).
//
// From M ü + D u̇ + K u = B₀ f (B₀'s columns γ_i b_i, one per input) and the sensor rows
// y = C₀ u + C₁ u̇ + C₂ ü, with the state x = (u, u̇):
//
//   ẋ = A x + B f,   A = [ 0  I ; −M⁻¹K  −M⁻¹D ],   B = [ 0 ; M⁻¹B₀ ]
//   y = C x + D f,   C = [ C₀ − C₂M⁻¹K   C₁ − C₂M⁻¹D ],   D = C₂ M⁻¹ B₀
//
// (an accelerometer reads ü = M⁻¹(B₀ f − K u − D u̇), hence its feed-through). The units are the
// scenario's: states in its length and angle units, inputs and outputs in the units of its inputs
// and sensors.
//
// The modal model beside it: the undamped modes K φ = ω² M φ, mass-normalised (φᵀ M φ = 1), each
// with the damping ratio ζ = φᵀ D φ / (2 ω) of the modal coordinate (exact for damping that the
// modes diagonalise, such as the square-root and Kelvin–Voigt laws of a uniform beam), and its
// shapes at the outputs (C₀ φ, C₁ φ, C₂ φ by sensor order) and at the inputs (B₀ᵀ φ, the modal
// participation of each input). Rigid-body modes (ω below rigid_floor, fe/modal.h) have ζ = NaN.
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "scoleid/identify/fe/structural_model.h"

namespace scoleid::identify {

struct StateSpace {
  Eigen::MatrixXd A, B, C, D;
  std::vector<std::string> inputs, outputs;  // names, in the scenario's order
  std::vector<int> output_order;             // 0 displacement-like, 1 velocity, 2 acceleration
};

struct ModalModel {
  Eigen::VectorXd omega;          // rad/s, ascending
  Eigen::VectorXd zeta;           // modal damping ratio (NaN for rigid-body modes)
  Eigen::MatrixXd output_shapes;  // outputs × modes: the sensor's reading per unit modal coordinate
  Eigen::MatrixXd input_shapes;   // inputs × modes: γ_i b_iᵀ φ
  Eigen::MatrixXd mass_shapes;    // DOF × modes: M φ (φ mass-normalised, φᵀ M φ = 1)
  std::vector<std::string> inputs, outputs;
};

// The model at coefficients c (Parameterization::coefficients of an estimate).
StateSpace state_space(const StructuralModel& model, const VectorXd& c);
// Every mode (a dense solution); or, given `elastic` > 0 on a model large enough for the sparse
// solver to pay (fe/lowest_modes.h), the rigid-body modes and the lowest `elastic` elastic ones
// only. A rigid-body mode is one below rigid_floor (fe/modal.h) either way.
ModalModel modal_model(const StructuralModel& model, const VectorXd& c, int elastic = 0);

}  // namespace scoleid::identify
