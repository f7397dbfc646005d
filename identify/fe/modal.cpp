#include "scoleid/identify/fe/modal.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <complex>
#include <limits>

#include "scoleid/io/interrupt.h"

namespace scoleid::identify {

namespace {

std::vector<double> natural_frequencies_now(const SparseMatrix& M, const SparseMatrix& K) {
  const MatrixXd Md(M), Kd(K);
  Eigen::GeneralizedSelfAdjointEigenSolver<MatrixXd> es(Kd, Md, Eigen::EigenvaluesOnly);
  std::vector<double> w;
  for (int i = 0; i < es.eigenvalues().size(); ++i) w.push_back(std::sqrt(std::max(0.0, es.eigenvalues()[i])));
  return w;
}

NaturalModes natural_modes_now(const SparseMatrix& M, const SparseMatrix& K) {
  const MatrixXd Md(M), Kd(K);
  double ratio = 0.0;
  for (int i = 0; i < Md.rows(); ++i)
    if (Md(i, i) > 0) ratio = std::max(ratio, Kd(i, i) / Md(i, i));
  const double sigma = ratio > 0 ? 1e-6 * ratio : 1.0;
  Eigen::GeneralizedSelfAdjointEigenSolver<MatrixXd> es(Md, Kd + sigma * Md, Eigen::ComputeEigenvectors | Eigen::Ax_lBx);
  const int n = static_cast<int>(Md.rows());
  NaturalModes m;
  m.omega.resize(n);
  m.vectors.resize(n, n);
  // μ descending is ω ascending.
  for (int k = 0; k < n; ++k) {
    const int i = n - 1 - k;
    const double mu = es.eigenvalues()[i];
    m.omega[k] = mu > 0 ? std::sqrt(std::max(0.0, 1.0 / mu - sigma)) : std::numeric_limits<double>::infinity();
    VectorXd v = es.eigenvectors().col(i);
    const double mm = v.dot(Md * v);
    m.vectors.col(k) = mm > 0 ? VectorXd(v / std::sqrt(mm)) : v;
  }
  m.floor = 1e-4 * std::sqrt(sigma);
  return m;
}

std::vector<DampedMode> damped_modes_now(const MatrixXd& M, const MatrixXd& D, const MatrixXd& K) {
  const Eigen::Index n = M.rows();
  std::vector<DampedMode> out;
  if (n == 0) return out;
  const auto symmetric = [](const MatrixXd& A) {
    return (A - A.transpose()).cwiseAbs().maxCoeff() <= 1e-12 * std::max(A.cwiseAbs().maxCoeff(), 1e-300);
  };
  MatrixXd A = MatrixXd::Zero(2 * n, 2 * n);
  double omega_max = 0.0;
  double floor = -1.0;  // below it a root is a rigid-body root (header)
  bool modal = false;
  if (symmetric(M) && symmetric(K)) {
    // Undamped modes from the shifted problem M φ = μ (K + σM) φ, μ = 1/(ω² + σ), as in
    // natural_modes: the low modes come out to relative accuracy ~ε (ω² + σ)/ω², not ε ω_max²/ω².
    double ratio = 0.0;
    for (Eigen::Index i = 0; i < n; ++i)
      if (M(i, i) > 0) ratio = std::max(ratio, K(i, i) / M(i, i));
    const double sigma = ratio > 0 ? 1e-6 * ratio : 1.0;
    const MatrixXd B = K + sigma * M;
    if (Eigen::LLT<MatrixXd>(B).info() == Eigen::Success) {
      const Eigen::GeneralizedSelfAdjointEigenSolver<MatrixXd> es(M, B, Eigen::ComputeEigenvectors | Eigen::Ax_lBx);
      const VectorXd mu = es.eigenvalues();
      if (es.info() == Eigen::Success && mu.minCoeff() > 0.0) {
        // φᵀ B φ = 1, so φᵀ M φ = μ: Φ = φ/√μ is M-orthonormal, Φᵀ K Φ = Λ = 1/μ − σ.
        const MatrixXd Phi = es.eigenvectors() * mu.cwiseSqrt().cwiseInverse().asDiagonal();
        const MatrixXd Dq = Phi.transpose() * D * Phi;
        for (Eigen::Index i = 0; i < n; ++i) {
          const double lam = 1.0 / mu[i] - sigma, w = std::sqrt(std::abs(lam));
          omega_max = std::max(omega_max, w);
          A(i, n + i) = w;
          A(n + i, i) = lam >= 0.0 ? -w : w;
        }
        A.bottomRightCorner(n, n) = -Dq;
        modal = true;
        floor = 1e-4 * std::sqrt(sigma);  // natural_modes' floor, rigid_floor
      }
    }
  }
  if (!modal) {
    const Eigen::PartialPivLU<MatrixXd> lu(M);
    const MatrixXd MK = lu.solve(K), MD = lu.solve(D);
    A.topRightCorner(n, n).setIdentity();
    A.bottomLeftCorner(n, n) = -MK;
    A.bottomRightCorner(n, n) = -MD;
    const Eigen::EigenSolver<MatrixXd> ek(MK, false);
    omega_max = std::sqrt(ek.eigenvalues().cwiseAbs().maxCoeff());
  }
  const Eigen::EigenSolver<MatrixXd> es(A, false);
  if (!modal) floor = 1e-6 * omega_max;
  for (Eigen::Index i = 0; i < es.eigenvalues().size(); ++i) {
    const std::complex<double> l = es.eigenvalues()[i];
    const double r = std::abs(l);
    if (!(r >= floor) || r == 0.0 || l.imag() < 0.0) continue;
    out.push_back({r, -l.real() / r, l.imag()});
  }
  std::sort(out.begin(), out.end(), [](const DampedMode& a, const DampedMode& b) { return a.omega < b.omega; });
  return out;
}

}  // namespace

double rigid_floor(const SparseMatrix& M, const SparseMatrix& K) {
  double ratio = 0.0;
  for (Eigen::Index i = 0; i < M.rows(); ++i) {
    const double m = M.coeff(i, i);
    if (m > 0) ratio = std::max(ratio, K.coeff(i, i) / m);
  }
  return 1e-4 * std::sqrt(ratio > 0 ? 1e-6 * ratio : 1.0);
}

// Each dense eigen solve runs through io::interruptible (a fine mesh takes minutes in Eigen, which
// cannot check for a signal): its body owns copies of its (sparse or small) arguments.

std::vector<double> natural_frequencies(const SparseMatrix& M, const SparseMatrix& K) {
  return io::interruptible([M, K] { return natural_frequencies_now(M, K); });
}

NaturalModes natural_modes(const SparseMatrix& M, const SparseMatrix& K) {
  return io::interruptible([M, K] { return natural_modes_now(M, K); });
}

std::vector<DampedMode> damped_modes(const MatrixXd& M, const MatrixXd& D, const MatrixXd& K) {
  return io::interruptible([M, D, K] { return damped_modes_now(M, D, K); });
}

double dense_eigen_seconds(int n, bool vectors) {
  constexpr int kCalibration = 256;
  static const std::array<double, 2> seconds = [] {
    std::vector<Eigen::Triplet<double>> k, m;
    for (int i = 0; i < kCalibration; ++i) {
      k.emplace_back(i, i, 2.0);
      if (i + 1 < kCalibration) k.emplace_back(i, i + 1, -1.0), k.emplace_back(i + 1, i, -1.0);
      m.emplace_back(i, i, 1.0);
    }
    SparseMatrix K(kCalibration, kCalibration), M(kCalibration, kCalibration);
    K.setFromTriplets(k.begin(), k.end());
    M.setFromTriplets(m.begin(), m.end());
    std::array<double, 2> best{INFINITY, INFINITY};
    for (int rep = 0; rep < 2; ++rep)
      for (int v = 0; v < 2; ++v) {
        const auto t0 = std::chrono::steady_clock::now();
        if (v) natural_modes_now(M, K);
        else natural_frequencies_now(M, K);
        best[static_cast<std::size_t>(v)] =
            std::min(best[static_cast<std::size_t>(v)], std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      }
    return best;
  }();
  const double r = static_cast<double>(n) / kCalibration;
  return seconds[vectors ? 1 : 0] * r * r * r;
}

}  // namespace scoleid::identify
