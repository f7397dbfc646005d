#include "scoleid/identify/fe/lowest_modes.h"

#include <Eigen/Eigenvalues>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

#include "scoleid/io/interrupt.h"

namespace scoleid::identify {

namespace {

// The starting block: p columns of a fixed pseudo-random sequence (the same modes on every call).
MatrixXd start_block(Eigen::Index n, Eigen::Index p) {
  std::mt19937_64 gen(20261207);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  MatrixXd X(n, p);
  for (Eigen::Index j = 0; j < p; ++j)
    for (Eigen::Index i = 0; i < n; ++i) X(i, j) = u(gen);
  return X;
}

// The shift of the iteration: between an eighth and a half of the lowest eigenvalue above the
// rigid-body floor (Sturm counts at s = floor², 4 floor², 16 floor², … until one more mode lies
// below s). Low enough that the wanted μ = 1/(ω² + σ) are well apart and ω² = 1/μ − σ loses nothing
// to cancellation; above zero, so K + σM is positive definite with rigid-body modes.
double iteration_shift(const SparseMatrix& M, const SparseMatrix& K, double floor2) {
  const int rigid = modes_below(M, K, std::sqrt(floor2));
  if (rigid < 0) throw LowestModesFailure("lowest_modes: the Sturm count at the rigid-body floor broke down");
  double s = 4.0 * floor2;
  for (int k = 0; k < 200; ++k, s *= 4.0) {
    const int below = modes_below(M, K, std::sqrt(s));
    if (below > rigid) return s / 8.0;
    if (below < 0) s *= 1.01;  // s on an eigenvalue: try beside it
  }
  throw LowestModesFailure("lowest_modes: no mode above the rigid-body floor");
}

struct Ritz {
  MatrixXd X, BX;  // B-orthonormal Ritz vectors and B X
  VectorXd mu;     // descending
  VectorXd residual;
};

// One step: X̄ = B⁻¹ M X, Rayleigh–Ritz in the B inner product. `residual` of the incoming
// vectors: ‖X̄_i − μ_i X_i‖_B / μ_i.
template <class Factor>
bool iterate(const Factor& B, const SparseMatrix& M, Ritz& r) {
  const MatrixXd Y = M * r.X;
  const MatrixXd Xb = B.solve(Y);
  if (!Xb.allFinite()) return false;
  if (r.mu.size() == r.X.cols()) {
    r.residual.resize(r.mu.size());
    for (Eigen::Index i = 0; i < r.mu.size(); ++i) {
      const VectorXd d = Xb.col(i) - r.mu[i] * r.X.col(i);
      const VectorXd Bd = Y.col(i) - r.mu[i] * r.BX.col(i);
      r.residual[i] = std::sqrt(std::max(0.0, d.dot(Bd))) / r.mu[i];
    }
  }
  MatrixXd G = Xb.transpose() * Y;  // X̄ᵀ B X̄
  G = 0.5 * (G + G.transpose());
  const Eigen::LLT<MatrixXd> llt(G);
  if (llt.info() != Eigen::Success) return false;
  const MatrixXd Rinv = llt.matrixU().solve(MatrixXd::Identity(G.rows(), G.cols()));
  const MatrixXd Z = Xb * Rinv;
  MatrixXd H = Z.transpose() * (M * Z);
  H = 0.5 * (H + H.transpose());
  const Eigen::SelfAdjointEigenSolver<MatrixXd> es(H);
  if (es.info() != Eigen::Success) return false;
  const Eigen::Index p = H.rows();
  MatrixXd S(p, p);
  r.mu.resize(p);
  for (Eigen::Index k = 0; k < p; ++k) {  // descending μ
    r.mu[k] = es.eigenvalues()[p - 1 - k];
    S.col(k) = es.eigenvectors().col(p - 1 - k);
  }
  r.X = Z * S;
  r.BX = Y * (Rinv * S);  // B Z = B X̄ R⁻¹ = Y R⁻¹
  return true;
}

NaturalModes lowest_modes_now(const SparseMatrix& M, const SparseMatrix& K, const LowestModesOptions& o,
                              LowestModesSummary& s) {
  const Eigen::Index n = M.rows();
  const double floor = rigid_floor(M, K);
  const double sigma = iteration_shift(M, K, floor * floor);
  SparseMatrix B = K + sigma * M;
  B.makeCompressed();
  const Eigen::SimplicialLLT<SparseMatrix> factor(B);
  if (factor.info() != Eigen::Success)
    throw LowestModesFailure("lowest_modes: K + sigma M is not positive definite (sigma " + std::to_string(sigma) + ")");
  int q = std::max(o.count, 0);
  if (o.below_omega > 0) {
    const int below = modes_below(M, K, o.below_omega);
    if (below < 0) throw LowestModesFailure("lowest_modes: the Sturm count at the band's edge broke down");
    q = std::max(q, below);
  }
  q = std::max(q, o.flexible);
  Ritz r;
  for (;;) {
    s.wanted = static_cast<int>(std::min<Eigen::Index>(q, n));
    if (s.wanted == 0) return NaturalModes{VectorXd(0), MatrixXd(n, 0), floor};
    const Eigen::Index p = std::min<Eigen::Index>(n, std::max(2 * s.wanted, s.wanted + 8));
    s.subspace = static_cast<int>(p);
    // Restarting with more modes keeps what has converged.
    MatrixXd X = start_block(n, p);
    if (r.X.cols() > 0) X.leftCols(std::min(p, r.X.cols())) = r.X.leftCols(std::min(p, r.X.cols()));
    r = Ritz{X, MatrixXd(), VectorXd(), VectorXd()};
    if (!iterate(factor, M, r)) throw LowestModesFailure("lowest_modes: the starting block is degenerate");
    s.converged = false;
    for (int it = 0; it < o.max_iterations; ++it) {
      io::check_interrupt();
      if (!iterate(factor, M, r)) throw LowestModesFailure("lowest_modes: the subspace lost its rank");
      s.iterations = it + 1;
      s.residual = r.residual.head(s.wanted).maxCoeff();
      if (s.residual <= o.tolerance) {
        s.converged = true;
        break;
      }
    }
    if (!s.converged)
      throw LowestModesFailure("lowest_modes: " + std::to_string(s.wanted) + " modes not converged in " +
                               std::to_string(s.iterations) + " iterations (residual " + std::to_string(s.residual) + ")");
    int rigid = 0;
    for (Eigen::Index k = 0; k < s.wanted; ++k)
      if (std::sqrt(std::max(0.0, 1.0 / r.mu[k] - sigma)) < floor) ++rigid;
    if (rigid + o.flexible <= q || q >= n) break;
    q = rigid + o.flexible;
  }
  NaturalModes m;
  m.floor = floor;
  m.omega.resize(s.wanted);
  m.vectors.resize(n, s.wanted);
  for (Eigen::Index k = 0; k < s.wanted; ++k) {
    const double mu = r.mu[k];
    m.omega[k] = mu > 0 ? std::sqrt(std::max(0.0, 1.0 / mu - sigma)) : std::numeric_limits<double>::infinity();
    const VectorXd v = r.X.col(k);
    const double mm = v.dot(M * v);  // = μ for a B-normalised eigenvector
    m.vectors.col(k) = mm > 0 ? VectorXd(v / std::sqrt(mm)) : v;
  }
  return m;
}

}  // namespace

int modes_below(const SparseMatrix& M, const SparseMatrix& K, double omega) {
  SparseMatrix A = K - (omega * omega) * M;
  A.makeCompressed();
  const Eigen::SimplicialLDLT<SparseMatrix> ldlt(A);
  if (ldlt.info() != Eigen::Success) return -1;
  const VectorXd d = ldlt.vectorD();
  int negative = 0;
  for (Eigen::Index i = 0; i < d.size(); ++i) {
    if (!std::isfinite(d[i]) || d[i] == 0.0) return -1;
    negative += d[i] < 0.0;
  }
  return negative;
}

NaturalModes lowest_modes(const SparseMatrix& M, const SparseMatrix& K, const LowestModesOptions& options,
                          LowestModesSummary* summary) {
  // Each iteration checks for a signal (a factorisation of a banded B takes milliseconds).
  LowestModesSummary s;
  NaturalModes m = lowest_modes_now(M, K, options, s);
  if (summary) *summary = s;
  return m;
}

NaturalModes few_or_all_modes(const SparseMatrix& M, const SparseMatrix& K, const LowestModesOptions& options) {
  const int n = static_cast<int>(M.rows());
  int wanted = std::max(options.count, options.flexible + 6);
  if (options.below_omega > 0 && n >= kSparseModesFrom) wanted = std::max(wanted, modes_below(M, K, options.below_omega));
  if (wanted >= 0 && sparse_modes_pay(n, wanted)) {
    try {
      return lowest_modes(M, K, options);
    } catch (const LowestModesFailure&) {
      // the dense solution below
    }
  }
  return natural_modes(M, K);
}

}  // namespace scoleid::identify
