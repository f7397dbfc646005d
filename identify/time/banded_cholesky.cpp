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

BandedCholesky::Shape BandedCholesky::shape(const Eigen::SparseMatrix<double>& A, int max_border) {
  const int n = static_cast<int>(A.rows());
  // reach[i]: the farthest coupling to the left of row i (symmetric pattern: either triangle).
  std::vector<int> reach(static_cast<std::size_t>(n), 0);
  for (int k = 0; k < A.outerSize(); ++k)
    for (Eigen::SparseMatrix<double>::InnerIterator it(A, k); it; ++it) {
      const int i = static_cast<int>(std::max(it.row(), it.col())), j = static_cast<int>(std::min(it.row(), it.col()));
      reach[static_cast<std::size_t>(i)] = std::max(reach[static_cast<std::size_t>(i)], i - j);
    }
  // prefix[m] = half bandwidth of the leading m rows.
  std::vector<int> prefix(static_cast<std::size_t>(n) + 1, 0);
  for (int i = 0; i < n; ++i) prefix[static_cast<std::size_t>(i) + 1] = std::max(prefix[static_cast<std::size_t>(i)], reach[static_cast<std::size_t>(i)]);
  Shape best{prefix[static_cast<std::size_t>(n)], 0};
  auto cost = [n](int b, int k) {
    const double m = n - k;
    return m * (b + 1.0) * (b + 1.0) + k * m * (b + 1.0) + static_cast<double>(k) * k * n;
  };
  double best_cost = cost(best.band, 0);
  for (int k = 1; k <= std::min(max_border, n - 1); ++k) {
    const int b = prefix[static_cast<std::size_t>(n - k)];
    const double c = cost(b, k);
    if (c < 0.999 * best_cost) {
      best = {b, k};
      best_cost = c;
    }
  }
  return best;
}

void BandedCholesky::resize(int n, int b, int border) {
  if (border < 0 || border > n) throw std::invalid_argument("BandedCholesky: border outside [0, n]");
  n_ = n;
  b_ = b;
  nb_ = n - border;
  data_.assign(static_cast<std::size_t>(nb_) * (b + 1) + static_cast<std::size_t>(border) * n, 0.0);
}

void BandedCholesky::set_zero() { std::fill(data_.begin(), data_.end(), 0.0); }

void BandedCholesky::assign(const Eigen::SparseMatrix<double>& A) {
  set_zero();
  for (int k = 0; k < A.outerSize(); ++k)
    for (Eigen::SparseMatrix<double>::InnerIterator it(A, k); it; ++it) {
      const int i = static_cast<int>(it.row()), j = static_cast<int>(it.col());
      if (j > i) continue;
      if (!fits(i, j)) throw std::logic_error("BandedCholesky::assign: entry outside band and border");
      at(i, j) = it.value();
    }
}

bool BandedCholesky::factorize() {
  inv_diag_.clear();  // set again only when the factorisation succeeds
  const int w = b_ + 1;
  double* L = data_.data();
  // Band rows: L_ij for j ∈ [i − b, i] only depends on band rows.
  for (int i = 0; i < nb_; ++i) {
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
  // Border rows: dense; against a band row j only its band [j − b, j) contributes.
  for (int i = nb_; i < n_; ++i) {
    double* Li = L + offset(i, 0);
    for (int j = 0; j <= i; ++j) {
      double s = Li[j];
      if (j < nb_) {
        const double* Lj = L + static_cast<std::size_t>(j) * w;
        for (int k = std::max(0, j - b_); k < j; ++k) s -= Li[k] * Lj[k - j + b_];
        Li[j] = s / Lj[b_];
      } else {
        const double* Lj = L + offset(j, 0);
        for (int k = 0; k < j; ++k) s -= Li[k] * Lj[k];
        if (i == j) {
          if (!(s > 0.0)) return false;
          Li[j] = std::sqrt(s);
        } else {
          Li[j] = s / Lj[j];
        }
      }
    }
  }
  inv_diag_.resize(static_cast<std::size_t>(n_));
  for (int i = 0; i < n_; ++i) inv_diag_[static_cast<std::size_t>(i)] = 1.0 / L[offset(i, i)];
  return true;
}

void BandedCholesky::solve_in_place(double* x) const { solve_in_place(x, 1, n_); }

void BandedCholesky::solve_in_place(double* X, int columns, std::ptrdiff_t ld) const {
  if (columns > 1 && ld < n_) throw std::invalid_argument("BandedCholesky::solve_in_place: leading dimension below n");
  if (inv_diag_.size() != static_cast<std::size_t>(n_)) throw std::logic_error("BandedCholesky: solve before a successful factorize");
  // Both sweeps read L by rows, which are contiguous in storage: L y = r by dot products with
  // row i, Lᵀ x = y by axpys with row i (column-oriented back substitution). Each row is applied
  // to every column before the next row: one column is a chain of dependent operations (row i
  // needs row i − 1), several columns are independent chains the processor overlaps. Every
  // column sees the same operations in the same order, so a column's result does not depend on
  // how many are solved together.
  const int w = b_ + 1;
  const double* L = data_.data();
  const double* inv = inv_diag_.data();
  auto col = [X, ld](int j) { return X + static_cast<std::ptrdiff_t>(j) * ld; };
  for (int i = 0; i < nb_; ++i) {
    const int k0 = std::max(0, i - b_);
    const double* Li = L + static_cast<std::size_t>(i) * w + (k0 - i + b_);
    for (int j = 0; j < columns; ++j) {
      double* x = col(j);
      double s = x[i];
      for (int k = k0; k < i; ++k) s -= Li[k - k0] * x[k];
      x[i] = s * inv[i];
    }
  }
  for (int i = nb_; i < n_; ++i) {
    const double* Li = L + offset(i, 0);
    for (int j = 0; j < columns; ++j) {
      double* x = col(j);
      double s = x[i];
      for (int k = 0; k < i; ++k) s -= Li[k] * x[k];
      x[i] = s * inv[i];
    }
  }
  for (int i = n_ - 1; i >= nb_; --i) {
    const double* Li = L + offset(i, 0);
    for (int j = 0; j < columns; ++j) {
      double* x = col(j);
      const double xi = (x[i] *= inv[i]);
      for (int k = 0; k < i; ++k) x[k] -= Li[k] * xi;
    }
  }
  for (int i = nb_ - 1; i >= 0; --i) {
    const int k0 = std::max(0, i - b_);
    const double* Lk = L + static_cast<std::size_t>(i) * w + (k0 - i + b_);
    for (int j = 0; j < columns; ++j) {
      double* x = col(j);
      const double xi = (x[i] *= inv[i]);
      for (int k = k0; k < i; ++k) x[k] -= Lk[k - k0] * xi;
    }
  }
}

}  // namespace scoleid::identify
