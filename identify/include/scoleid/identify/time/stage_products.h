#pragma once
// The products of a stage's right-hand side (esdirk_stepper.h)
//
//     out = (r − D v) − K x
//
// over several columns at once (the state and its tangents), with D and K the damping and
// stiffness matrices, copied by rows: each entry of a product is a sum along a row (independent
// multiply-adds) rather than a column scatter, whose stores depend on each other.
//
// Bit for bit: each row sum is accumulated from zero over the row's stored entries in their order
// and then subtracted, as Eigen's row-major sparse × dense product forms `out.noalias() -= D * v`,
// so every column's result is that of the two Eigen products, whatever the number of columns
// (a column of tangents is the same number in a one-column and in a many-column sweep).
//
// Speed: four columns go through a row's entries together (four independent chains, one index
// load for four), a single column two rows at a time. D and K assembled on one pattern (as
// newton_matrix.h builds them) share its indices; a D with no nonzero entry is not multiplied
// (its sums are zero: r − 0 = r exactly).
#include <Eigen/Sparse>

#include "scoleid/identify/fe/structural_model.h"

namespace scoleid::identify {

class StageProducts {
public:
  StageProducts(const SparseMatrix& D, const SparseMatrix& K);
  int rows() const { return static_cast<int>(K_.rows()); }
  // out(:, c) = (r(:, c) − D v(:, c)) − K x(:, c) for c < cols; every array n × cols, column-major
  // with leading dimension n = rows(). `out` may be `r`, not v or x.
  void subtract(const double* v, const double* x, const double* r, double* out, int cols) const;

private:
  Eigen::SparseMatrix<double, Eigen::RowMajor> D_, K_;
  bool damped_ = true;          // D has a nonzero entry
  bool shared_pattern_ = false;  // D and K store the same pattern
};

}  // namespace scoleid::identify
