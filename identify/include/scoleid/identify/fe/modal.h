#pragma once
// Natural frequencies of the undamped FE model: K φ = ω² M φ (dense generalized symmetric
// eigenproblem; for verification and reports, not for time stepping).
#include <vector>

#include "scoleid/identify/fe/structural_model.h"

namespace scoleid::identify {

// Angular frequencies ω_k [rad/s], ascending; rigid-body modes appear as ≈ 0.
std::vector<double> natural_frequencies(const SparseMatrix& M, const SparseMatrix& K);

// All modes: ω_k ascending and the M-orthonormal mode vectors φ_k (columns), from the shifted
// problem M φ = μ (K + σ M) φ, μ = 1 / (ω² + σ), σ = 1e-6 max_i K_ii / M_ii. The dense solver's
// absolute error in μ is a few ε μ_max = ε / σ, so ω² comes out with absolute error about
// ε (ω² + σ)² / σ: rigid-body modes at ≈ sqrt(ε σ) (not at sqrt(ε) ω_max as without the shift)
// and the low flexible modes to relative ε ω² / σ. The high modes lose accuracy; they are not
// what this is for. `floor`: frequencies below it (1e-4 sqrt σ) are rigid-body modes.
struct NaturalModes {
  VectorXd omega;
  MatrixXd vectors;
  double floor = 0.0;
};
NaturalModes natural_modes(const SparseMatrix& M, const SparseMatrix& K);

}  // namespace scoleid::identify
