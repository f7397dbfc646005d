#include "scoleid/identify/fe/modal.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>

namespace scoleid::identify {

std::vector<double> natural_frequencies(const SparseMatrix& M, const SparseMatrix& K) {
  const MatrixXd Md(M), Kd(K);
  Eigen::GeneralizedSelfAdjointEigenSolver<MatrixXd> es(Kd, Md, Eigen::EigenvaluesOnly);
  std::vector<double> w;
  for (int i = 0; i < es.eigenvalues().size(); ++i) w.push_back(std::sqrt(std::max(0.0, es.eigenvalues()[i])));
  return w;
}

NaturalModes natural_modes(const SparseMatrix& M, const SparseMatrix& K) {
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

}  // namespace scoleid::identify
