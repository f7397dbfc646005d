#pragma once
// A linear structural model whose operators are affine in a coefficient vector c:
//
//   M(c) ü + D(c) u̇ + K(c) u = Σ_i γ_i(c) b_i f_i(t),     y = C u
//
//   M(c) = Σ_terms c_j M_j,  D(c) = Σ c_j D_j,  K(c) = Σ c_j K_j   (coefficient index -1 = constant 1)
//
// Every physical parameter enters through the coefficients (mass per length, sectional EI,
// Kelvin–Voigt coefficients, ...), so the first variation needed by the costate gradient is
//   ∂J/∂c_j = ∫₀ᵀ pᵀ (M_j ü + D_j u̇ + K_j u − b_j f) dt
// a sum over the terms that carry c_j; its cost is that of one pass over all terms, whatever
// the number of coefficients (docs/theory.md §6; paper Eq. 25).
#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <string>
#include <vector>

#include "scoleid/io/types.h"

namespace scoleid::identify {

using SparseMatrix = Eigen::SparseMatrix<double>;
using Eigen::MatrixXd;
using Eigen::VectorXd;

struct OperatorTerm {
  SparseMatrix matrix;
  int coefficient = -1;  // index into c, or -1 for a constant term
};

struct ModelInput {
  std::string name;
  VectorXd vector;        // b_i (generalised load for a unit input)
  int coefficient = -1;   // γ_i = c[coefficient], or 1
};

// A sensor is a row on u, u̇ or ü: y_k = C_k u^(order).
struct ModelSensor {
  std::string name;
  io::SensorKind kind = io::SensorKind::Displacement;  // order: io::derivative_order(kind)
  int order = 0;          // derivative the row acts on
  Eigen::RowVectorXd row; // C_k
};

struct StructuralModel {
  int ndof = 0;
  int ncoef = 0;
  std::vector<std::string> coefficient_names;
  std::vector<int> dof_group;             // for error weights: DOFs of like units share a group
  std::vector<OperatorTerm> mass, damping, stiffness;
  std::vector<ModelInput> inputs;
  std::vector<ModelSensor> sensors;

  SparseMatrix assemble(const std::vector<OperatorTerm>& terms, const VectorXd& c) const;
  double input_scale(int i, const VectorXd& c) const {
    const int k = inputs[static_cast<std::size_t>(i)].coefficient;
    return k < 0 ? 1.0 : c[k];
  }
  // Output matrix C_order (sensors × ndof): the rows of the sensors acting on the order-th time
  // derivative of u, zero rows for the others; y = C_0 u + C_1 u̇ + C_2 ü.
  MatrixXd output_matrix(int order = 0) const;
  // Whether any sensor acts on u̇ or ü.
  bool has_rate_outputs() const;
};

// Assembled operators at one coefficient vector.
struct AssembledModel {
  SparseMatrix M, D, K;
  std::vector<VectorXd> loads;  // γ_i b_i
};

AssembledModel assemble(const StructuralModel& model, const VectorXd& c);

}  // namespace scoleid::identify
