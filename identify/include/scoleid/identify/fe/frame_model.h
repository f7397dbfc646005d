#pragma once
// Finite-element model of the planar frame of docs/theory.md §2.6, in the form of
// structural_model.h. Storey k (height h_k, floor k at its top) has `columns` identical vertical
// Euler–Bernoulli columns, each clamped into the rigid floor below (the ground for k = 1) and the
// floor above. The columns are inextensible and the floors rigid, so to first order a floor
// neither rises nor turns: its one degree of freedom is its sway u_k, and a column's ends have
// w = u_{k−1}, u_k and w_s = 0. Along a column, with s the height:
//
//   ρA w_tt − (d_k w_st)_s + (τ EI_k w_sst)_ss + (EI_k w_ss)_ss = 0
//   d_k = 2 ζ √(ρA EI_k)   square-root (Chen–Russell) damping of the columns
//   τ EI_k                 Kelvin–Voigt damping with one time constant τ: D ⊇ τ K, so a frame
//                          with ζ = 0 damps mode j by exactly τ ω_j / 2
//   m_k ü_k = Σ_columns [shear of the storey below − shear of the storey above]_k + f_k(t)
//
// Hermite cubic elements (hermite_beam.h) on each column; interior nodes carry (w, w_s), the
// floors their sway. Coefficients c = [ρA, EI_1..EI_n, d_1..d_n, c_1..c_n, m_1..m_n]: M = ρA
// M_col + Σ m_k e_k e_kᵀ, K = Σ EI_k K_k, D = Σ (d_k G_k + c_k K_k), c_k = τ EI_k (K_k, G_k the
// unit-coefficient stiffness and slope products of storey k's columns). Loads and sensors at a height s on the first column, through
// its shape functions (at a floor's height: the floor's sway).
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "scoleid/identify/fe/structural_model.h"
#include "scoleid/identify/fe/structure.h"
#include "scoleid/identify/inverse/physical_parameterization.h"
#include "scoleid/io/scenario.h"

namespace scoleid::identify {

struct FrameFE {
  StructuralModel model;
  double height = 0.0;
  int elements = 0;  // along the height, on one column
  int storeys = 0;
  int columns = 0;
  std::vector<double> base;               // height of storey k's foot, k = 0..n (base[n] = height)
  std::vector<int> storey_elements;       // elements on each column of storey k
  // The DOFs (w, w_s) of node j of column c of storey k (dofs[k][c][j]); -1 where held.
  std::vector<std::vector<std::vector<std::array<int, 2>>>> dofs;

  int coef_rho_A() const { return 0; }
  int coef_EI(int k) const { return 1 + k; }
  int coef_chen_russell(int k) const { return 1 + storeys + k; }
  int coef_kelvin_voigt(int k) const { return 1 + 2 * storeys + k; }
  int coef_floor_mass(int k) const { return 1 + 3 * storeys + k; }
  int floor_dof(int k) const { return k; }  // floor k + 1's sway

  // Rows on the DOF vector at height s on the first column: w (derivative 0), w_s (1).
  Eigen::RowVectorXd row(double s, int derivative) const;
};

// Forces (horizontal) and moments at heights on the first column; sensors of kind displacement,
// rotation, velocity, acceleration. A validated scenario's (io::validate_scenario); anything else
// is a std::logic_error.
FrameFE build_frame(const io::FrameSpec& frame, int elements, const std::vector<io::InputSpec>& inputs,
                    const std::vector<io::SensorSpec>& sensors);

// Coefficients at a frame's values.
VectorXd frame_coefficients(const FrameFE& fe, const io::FrameSpec& frame);

// φ = [ρA, EI_1..EI_n, ζ, τ, floor_mass_1..floor_mass_n], the group EI (every storey).
ParameterSpace frame_parameter_space(const FrameFE& fe, const io::FrameSpec& frame);

// The identifier's view of a frame scenario (fe/structure.h); make_structure's registry row.
std::unique_ptr<FEStructure> make_frame_structure(const io::Scenario& sc, int elements);

}  // namespace scoleid::identify
