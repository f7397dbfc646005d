#pragma once
// The lowest natural modes of a large FE model, K φ = ω² M φ, without a dense eigen-solution
// (docs/theory.md §4.4).
//
// Sturm count. For any shift s, an LDLᵀ factorisation of K − s M is a congruence, so by
// Sylvester's law of inertia the number of negative entries of D is the number of eigenvalues
// ω² below s. One sparse factorisation therefore says exactly how many modes lie below a
// frequency Ω: the modes a record sampled at Nyquist frequency Ω can show.
//
// Subspace iteration (Bathe's method) on a shifted problem
//   M φ = μ B φ,   B = K + σ M,   μ = 1 / (ω² + σ),
// σ between an eighth and a half of the lowest elastic ω² (found by Sturm counts at the rigid-body
// floor, 4×, 16×, … it): B is positive definite even with rigid-body modes, the wanted μ are well
// apart, and ω² = 1/μ − σ does not cancel. With X (n × p) B-orthonormal:
//   X̄ = B⁻¹ M X (one sparse Cholesky factorisation of B, p solves),
//   Rayleigh–Ritz: Z = X̄ R⁻¹ with Rᵀ R = X̄ᵀ B X̄ = X̄ᵀ (M X) (B-orthonormal),
//   Zᵀ M Z S = S diag(μ), X ← Z S, μ descending (ω ascending).
// Ritz vector i converges as (μ_{p+1}/μ_i)^k and its value twice as fast; p = max(2q, q + 8) for
// q wanted modes. Converged when every wanted mode's residual ‖B⁻¹ M x − μ x‖_B / μ ≤ tolerance
// (x B-normalised). Cost per iteration: p banded solves and products, O(n p²) for the Gram
// matrices; against O(n³) dense. Accuracy: like any backward-stable solver, ω_k² to about
// ε ω_max² absolute (docs/theory.md §4.4: on a fine beam mesh the fundamental's relative error
// grows as N⁴, for the dense solver too).
//
// The modes come out as natural_modes gives them: ω ascending, vectors M-orthonormal, `floor`
// rigid_floor(M, K) (below it a mode is a rigid-body mode).
#include <stdexcept>

#include "scoleid/identify/fe/modal.h"

namespace scoleid::identify {

// Models of at least this many degrees of freedom take the modes they need from lowest_modes
// when those are few (at most an eighth of the degrees of freedom): below it a dense solution
// takes well under a second, above it O(n³) grows to minutes.
constexpr int kSparseModesFrom = 1000;
inline bool sparse_modes_pay(int ndof, int wanted) { return ndof >= kSparseModesFrom && 8 * wanted <= ndof; }

// The number of eigenvalues ω² of K φ = ω² M φ below omega² (Sylvester's law of inertia on a
// sparse LDLᵀ of K − omega² M). −1 when the factorisation breaks down (a zero pivot: omega²
// on an eigenvalue to rounding).
int modes_below(const SparseMatrix& M, const SparseMatrix& K, double omega);

struct LowestModesOptions {
  double below_omega = 0.0;  // > 0: every mode with ω < below_omega (its Sturm count)
  int count = 0;             // at least this many of the lowest modes
  int flexible = 0;          // at least this many modes above the rigid-body floor
  double tolerance = 1e-10;  // relative residual of each wanted mode (see above)
  int max_iterations = 300;
};

struct LowestModesSummary {
  int wanted = 0;        // modes asked for (after the Sturm count and rigid-body modes)
  int subspace = 0;      // p
  int iterations = 0;
  double residual = 0.0; // the largest relative residual of a wanted mode at the end
  bool converged = false;
};

// Why the sparse solver gave no modes; its callers then take the dense solution.
struct LowestModesFailure : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The wanted modes, lowest first (NaturalModes as natural_modes returns them, fewer columns).
// Throws LowestModesFailure when B is not positive definite, the Sturm count breaks down or the
// iteration does not converge within max_iterations.
NaturalModes lowest_modes(const SparseMatrix& M, const SparseMatrix& K, const LowestModesOptions& options,
                          LowestModesSummary* summary = nullptr);

// lowest_modes where it pays (sparse_modes_pay for the modes `options` asks, six rigid-body modes
// allowed for `flexible`) and succeeds; natural_modes (every mode) otherwise.
NaturalModes few_or_all_modes(const SparseMatrix& M, const SparseMatrix& K, const LowestModesOptions& options);

}  // namespace scoleid::identify
