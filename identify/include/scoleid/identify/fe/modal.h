#pragma once
// Natural frequencies of the undamped FE model: K φ = ω² M φ (dense generalized symmetric
// eigenproblem; for verification and reports, not for time stepping).
#include <vector>

#include "scoleid/identify/fe/structural_model.h"

namespace scoleid::identify {

// Angular frequencies ω_k [rad/s], ascending; rigid-body modes appear as ≈ 0.
std::vector<double> natural_frequencies(const SparseMatrix& M, const SparseMatrix& K);

}  // namespace scoleid::identify
