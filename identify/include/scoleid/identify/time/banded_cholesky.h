#pragma once
// Cholesky factorisation A = L Lᵀ of a symmetric positive definite band matrix with half
// bandwidth b (A_ij = 0 for |i − j| > b): O(n b²) to factor, O(n b) to solve. The FE operators
// of a beam in natural node order have b = 3, so every solve in the time integrators is linear
// in the number of elements.
#include <Eigen/Sparse>
#include <vector>

namespace scoleid::identify {

class BandedCholesky {
public:
  // Half bandwidth of a sparse pattern (lower triangle inspected).
  static int bandwidth(const Eigen::SparseMatrix<double>& A);

  BandedCholesky() = default;
  BandedCholesky(int n, int b) { resize(n, b); }
  void resize(int n, int b);
  int size() const { return n_; }
  int half_bandwidth() const { return b_; }

  // Band storage: entry (i, j), i − b <= j <= i, lives at at(i, j).
  double& at(int i, int j) { return band_[static_cast<std::size_t>(i) * (b_ + 1) + (j - i + b_)]; }
  void set_zero();
  // Copies the lower triangle of a sparse matrix into the band (entries outside are an error).
  void assign(const Eigen::SparseMatrix<double>& A);
  // Factorises in place; false if the matrix is not positive definite.
  bool factorize();
  // Solves A x = r in place (x holds r on entry).
  void solve_in_place(double* x) const;

private:
  int n_ = 0, b_ = 0;
  std::vector<double> band_;
};

}  // namespace scoleid::identify
