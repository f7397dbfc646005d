#pragma once
// Cholesky factorisation A = L Lᵀ of a symmetric positive definite band matrix with half
// bandwidth b (A_ij = 0 for |i − j| > b) and an optional dense border: the last k rows (and
// columns) may couple with everything. The FE operators of a beam in natural node order have
// b = 3; SCOLE's mast nodes are banded and its six shuttle DOFs, ordered last, form the border
// (the root couples them to the first node, the mast's relative damping to the tip —
// docs/theory.md §4.3). An arrowhead matrix has no fill outside band + border, so the cost is
// O(n b² + n b k + n k²) to factor and O(n (b + k)) to solve: linear in the number of elements.
#include <Eigen/Sparse>
#include <cstddef>
#include <vector>

namespace scoleid::identify {

class BandedCholesky {
public:
  // Half bandwidth of a sparse pattern (lower triangle inspected), no border.
  static int bandwidth(const Eigen::SparseMatrix<double>& A);
  // Band and border for a pattern: the border k ∈ [0, max_border] (the last k rows) that
  // minimises the factorisation cost, b the half bandwidth of the leading n − k rows.
  struct Shape {
    int band = 0;
    int border = 0;
  };
  static Shape shape(const Eigen::SparseMatrix<double>& A, int max_border = 16);

  BandedCholesky() = default;
  BandedCholesky(int n, int b, int border = 0) { resize(n, b, border); }
  void resize(int n, int b, int border = 0);
  void resize(int n, const Shape& s) { resize(n, s.band, s.border); }
  int size() const { return n_; }
  int half_bandwidth() const { return b_; }
  int border() const { return n_ - nb_; }

  // Storage offset of the lower-triangle entry (i, j), j <= i, inside band or border (callers
  // check `fits` first): band rows i < n − k hold j ∈ [i − b, i]; border rows hold j ∈ [0, i].
  bool fits(int i, int j) const { return j <= i && (i >= nb_ || i - j <= b_); }
  std::size_t offset(int i, int j) const {
    return i < nb_ ? static_cast<std::size_t>(i) * (b_ + 1) + static_cast<std::size_t>(j - i + b_)
                   : static_cast<std::size_t>(nb_) * (b_ + 1) + static_cast<std::size_t>(i - nb_) * n_ + static_cast<std::size_t>(j);
  }
  double& at(int i, int j) { return data_[offset(i, j)]; }
  double* data() { return data_.data(); }
  void set_zero();
  // Copies the lower triangle of a sparse matrix (entries outside band and border are an error).
  void assign(const Eigen::SparseMatrix<double>& A);
  // Factorises in place; false if the matrix is not positive definite.
  bool factorize();
  // Solves A x = r in place (x holds r on entry); needs a successful factorize() since the last
  // change of the entries.
  void solve_in_place(double* x) const;
  // Solves A X = R in place for `columns` columns stored column-major with leading dimension ld
  // (X holds R on entry); each column's result is bit for bit that of the one-column solve.
  //
  // Two kernels, with the same operations in the same order for every column (so the same results
  // to the last bit): Automatic takes the interleaved one where the processor has 256-bit vectors
  // (AVX) — the columns copied into rows of four side by side, one vector operation for four
  // columns (a lone column padded to four: measured, it still gains) — and the scalar loops
  // elsewhere; Scalar always takes the scalar loops (for comparison and tests). No columns: nothing
  // is done.
  enum class Kernel { Automatic, Scalar };
  void solve_in_place(double* X, int columns, std::ptrdiff_t ld, Kernel kernel = Kernel::Automatic) const;

private:
  // The band's full rows go through loops with the bandwidth a compile-time constant up to this
  // one (banded_cholesky.cpp).
  static constexpr int kMaxUnrolledBand = 8;
  static constexpr int kColumnGroup = 16;  // columns solved together at most (more: in even groups)
  int n_ = 0, b_ = 0, nb_ = 0;  // nb_: rows in the band part (n − border)
  std::vector<double> data_;
  std::vector<double> inv_diag_;  // 1 / L_ii, set by factorize (a product in the sweeps, not a division)
};

}  // namespace scoleid::identify
