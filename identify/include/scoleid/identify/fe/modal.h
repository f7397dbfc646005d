#pragma once
// Natural frequencies of the undamped FE model: K φ = ω² M φ (dense generalized symmetric
// eigenproblem; for verification and reports, not for time stepping), and the damped modes of
// M ü + D u̇ + K u = 0.
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

// natural_modes' floor, 1e-4 √σ: below it a mode is a rigid-body mode. It scales with the
// model's highest frequencies (√σ ≈ 1e-3 ω_max) but lies five decades under them and four above
// where a solver puts a rigid-body mode (≈ √ε ω_max unshifted, √(ε σ) shifted); "10⁻⁶ of the
// highest frequency" instead would count a fine mesh's lowest elastic modes as rigid (a pinned
// beam's fundamental on 500 elements lies there, its two lowest on 1000).
double rigid_floor(const SparseMatrix& M, const SparseMatrix& K);

// Roughly how long natural_frequencies (vectors false) or natural_modes (true) takes on an
// n-degree-of-freedom model on this machine [s]: the solve's cost grows as n³, so one of 256
// degrees of freedom (a chain's stiffness, best of two) is timed once per process and scaled by
// (n/256)³. What a progress line can promise before a long solve; larger problems run out of
// cache, so the estimate tends to be low (tests/identify/api_test.cpp measures it).
double dense_eigen_seconds(int n, bool vectors);

// Damped modes of M ü + D u̇ + K u = 0 from the eigenvalues λ of the first-order system, computed
// densely and exactly (no proportional-damping or small-damping assumption):
//   omega   = |λ|, the undamped-equivalent frequency [rad/s]
//   zeta    = −Re λ / |λ|, the damping ratio
//   omega_d = Im λ, the damped frequency
// One entry per complex-conjugate pair (Im λ > 0). A real root is an entry of its own with
// omega = |λ|, zeta = ±1 (sign of −λ), omega_d = 0: an overdamped mode shows as two such entries,
// a damped rigid-body motion as one. Roots below a floor are rigid-body roots and are left out:
// on the symmetric path below, rigid_floor (natural_modes' floor, about 1e-7 ω_max: the shifted
// problem puts an exact zero at √(ε σ), and a fine mesh's lowest elastic modes lie above it); on
// the general path 1e-6 ω_max, ω_max the largest undamped frequency (√ of the largest |eigenvalue|
// of M⁻¹K), where the unshifted solver puts an exact zero at about √ε ω_max ≈ 1.5e-8 ω_max.
// Ascending in omega.
//
// Method. When M and K are symmetric and K + σM is positive definite (FE models; σ = 1e-6
// max_i K_ii/M_ii as in natural_modes), the undamped modes Φ (M-orthonormal, Φᵀ K Φ = Λ) come from
// the shifted problem of natural_modes, accurate to relative ~ε for the low modes, and the state
// z = (|Ω| q, q̇), u = Φ q, |Ω| = |Λ|^½, gives the 2n × 2n matrix [0 |Ω|; −sgn(Λ)|Ω| −Φᵀ D Φ],
// whose entries scale like ω rather than ω²: its eigenvalues have absolute error ~ ε ω_max
// instead of ~ ε ω_max². Otherwise (a non-symmetric K, e.g. from a numerical linearisation, or an
// unstable K) A = [0 I; −M⁻¹K −M⁻¹D]. Both go to Eigen::EigenSolver (real Schur form).
struct DampedMode {
  double omega = 0.0;    // |λ| [rad/s]
  double zeta = 0.0;     // −Re λ / |λ|
  double omega_d = 0.0;  // Im λ [rad/s]
};
std::vector<DampedMode> damped_modes(const MatrixXd& M, const MatrixXd& D, const MatrixXd& K);

}  // namespace scoleid::identify
