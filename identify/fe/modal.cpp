#include "scoleid/identify/fe/modal.h"

#include <Eigen/Eigenvalues>
#include <cmath>

namespace scoleid::identify {

std::vector<double> natural_frequencies(const SparseMatrix& M, const SparseMatrix& K) {
  const MatrixXd Md(M), Kd(K);
  Eigen::GeneralizedSelfAdjointEigenSolver<MatrixXd> es(Kd, Md, Eigen::EigenvaluesOnly);
  std::vector<double> w;
  for (int i = 0; i < es.eigenvalues().size(); ++i) w.push_back(std::sqrt(std::max(0.0, es.eigenvalues()[i])));
  return w;
}

}  // namespace scoleid::identify
