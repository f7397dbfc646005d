#include "scoleid/identify/time/banded_cholesky.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace scoleid::identify {

int BandedCholesky::bandwidth(const Eigen::SparseMatrix<double>& A) {
  int b = 0;
  for (int k = 0; k < A.outerSize(); ++k)
    for (Eigen::SparseMatrix<double>::InnerIterator it(A, k); it; ++it)
      b = std::max(b, static_cast<int>(std::abs(it.row() - it.col())));
  return b;
}

void BandedCholesky::resize(int n, int b) {
  n_ = n;
  b_ = b;
  band_.assign(static_cast<std::size_t>(n) * (b + 1), 0.0);
}

void BandedCholesky::set_zero() { std::fill(band_.begin(), band_.end(), 0.0); }

void BandedCholesky::assign(const Eigen::SparseMatrix<double>& A) {
  set_zero();
  for (int k = 0; k < A.outerSize(); ++k)
    for (Eigen::SparseMatrix<double>::InnerIterator it(A, k); it; ++it) {
      const int i = static_cast<int>(it.row()), j = static_cast<int>(it.col());
      if (j > i) continue;
      if (i - j > b_) throw std::logic_error("BandedCholesky::assign: entry outside the band");
      at(i, j) = it.value();
    }
}

bool BandedCholesky::factorize() {
  const int w = b_ + 1;
  double* L = band_.data();
  for (int i = 0; i < n_; ++i) {
    const int j0 = std::max(0, i - b_);
    for (int j = j0; j <= i; ++j) {
      double s = L[i * w + (j - i + b_)];
      const int k0 = std::max(j0, j - b_);
      for (int k = k0; k < j; ++k) s -= L[i * w + (k - i + b_)] * L[j * w + (k - j + b_)];
      if (i == j) {
        if (!(s > 0.0)) return false;
        L[i * w + b_] = std::sqrt(s);
      } else {
        L[i * w + (j - i + b_)] = s / L[j * w + b_];
      }
    }
  }
  return true;
}

void BandedCholesky::solve_in_place(double* x) const {
  // Both sweeps read L by rows, which are contiguous in the band storage: L y = r by dot
  // products with row i, Lᵀ x = y by axpys with row i (column-oriented back substitution).
  const int w = b_ + 1;
  const double* L = band_.data();
  for (int i = 0; i < n_; ++i) {
    const int k0 = std::max(0, i - b_);
    const double* Li = L + static_cast<std::size_t>(i) * w + (k0 - i + b_);
    double s = x[i];
    for (int k = k0; k < i; ++k) s -= *Li++ * x[k];
    x[i] = s / *Li;
  }
  for (int i = n_ - 1; i >= 0; --i) {
    const double* Li = L + static_cast<std::size_t>(i) * w;
    const double xi = (x[i] /= Li[b_]);
    const int k0 = std::max(0, i - b_);
    const double* Lk = Li + (k0 - i + b_);
    for (int k = k0; k < i; ++k) x[k] -= *Lk++ * xi;
  }
}

}  // namespace scoleid::identify
