// The stage kernels of the time steppers against the plain algorithms they restate:
//  - BandedCholesky::solve_in_place (its bandwidth-specialised loops, columns in groups; both
//    kernels, the interleaved vectors where the processor has them and the scalar loops) against a
//    textbook band-and-border forward and column-oriented back substitution written here: bit for
//    bit per column, for every bandwidth with and without a kernel of its own, with and without a
//    border, for column counts around the groups, and to rounding against a dense solve;
//  - StageProducts::subtract against Eigen's `out = r; out -= D v; out -= K x`: bit for bit, with D
//    and K on one pattern, with D zero, and on patterns that differ.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "scoleid/identify/time/banded_cholesky.h"
#include "scoleid/identify/time/stage_products.h"

using namespace scoleid::identify;
using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {

// A symmetric positive definite matrix with half bandwidth b in its first n − border rows and
// dense border rows and columns: M = B Bᵀ-like diagonal dominance on a random pattern.
SparseMatrix band_and_border(int n, int b, int border, unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Eigen::Triplet<double>> t;
  const int nb = n - border;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < i; ++j)
      if (i >= nb || i - j <= b) {
        const double a = u(gen);
        t.emplace_back(i, j, a);
        t.emplace_back(j, i, a);
      }
  for (int i = 0; i < n; ++i) t.emplace_back(i, i, 2.0 * (b + border) + 3.0 + u(gen));
  SparseMatrix S(n, n);
  S.setFromTriplets(t.begin(), t.end());
  return S;
}

// The textbook solve of L Lᵀ x = r on the dense lower factor Ld: forward by dot products over the
// factor's band and border, back substitution column by column from the last row.
VectorXd textbook_solve(const MatrixXd& Ld, int b, int nb, VectorXd x) {
  const int n = static_cast<int>(x.size());
  auto first = [&](int i) { return i < nb ? std::max(0, i - b) : 0; };
  for (int i = 0; i < n; ++i) {
    double s = x[i];
    for (int k = first(i); k < i; ++k) s -= Ld(i, k) * x[k];
    x[i] = s * (1.0 / Ld(i, i));
  }
  for (int i = n - 1; i >= 0; --i) {
    const double xi = (x[i] *= 1.0 / Ld(i, i));
    for (int k = first(i); k < i; ++k) x[k] -= Ld(i, k) * xi;
  }
  return x;
}

}  // namespace

TEST(BandedCholesky, EveryColumnIsTheTextbookSolveBitForBit) {
  for (int b : {0, 1, 2, 3, 5, 8, 9, 12})
    for (int border : {0, 3, 11}) {
      const int n = 41 + border;
      const SparseMatrix S = band_and_border(n, b, border, 17u * static_cast<unsigned>(b) + static_cast<unsigned>(border));
      BandedCholesky c;
      c.resize(n, BandedCholesky::Shape{b, border});
      c.assign(S);
      ASSERT_TRUE(c.factorize()) << "b " << b << " border " << border;
      // The factor as a dense lower triangle, read back through the storage.
      MatrixXd Ld = MatrixXd::Zero(n, n);
      for (int i = 0; i < n; ++i)
        for (int j = 0; j <= i; ++j)
          if (c.fits(i, j)) Ld(i, j) = c.data()[c.offset(i, j)];
      {  // no columns: nothing is touched
        MatrixXd R = MatrixXd::Random(n, 4), X = R;
        c.solve_in_place(X.data(), 0, n);
        EXPECT_TRUE(X == R);
      }
      for (int cols : {1, 2, 3, 4, 5, 7, 16, 17, 33, 37, 49})
        for (auto kernel : {BandedCholesky::Kernel::Automatic, BandedCholesky::Kernel::Scalar}) {
          const Eigen::Index ld = n + 5;  // a leading dimension beyond n
          MatrixXd R = MatrixXd::Random(ld, cols);
          MatrixXd X = R;
          c.solve_in_place(X.data(), cols, ld, kernel);
          const MatrixXd dense = MatrixXd(S).ldlt().solve(R.topRows(n));
          for (int j = 0; j < cols; ++j) {
            const VectorXd ref = textbook_solve(Ld, b, n - border, R.col(j).head(n));
            EXPECT_TRUE(X.col(j).head(n) == ref) << "b " << b << " border " << border << " columns " << cols << " column " << j
                                                 << (kernel == BandedCholesky::Kernel::Scalar ? " (scalar)" : "");
            EXPECT_TRUE(X.col(j).tail(5) == R.col(j).tail(5)) << "rows beyond n untouched";
            EXPECT_LT((X.col(j).head(n) - dense.col(j)).norm(), 1e-12 * dense.col(j).norm());
          }
        }
    }
}

namespace {
MatrixXd eigen_products(const SparseMatrix& D, const SparseMatrix& K, const MatrixXd& V, const MatrixXd& X,
                        const MatrixXd& R) {
  const Eigen::SparseMatrix<double, Eigen::RowMajor> Dr(D), Kr(K);
  MatrixXd out = R;
  for (Eigen::Index c = 0; c < R.cols(); ++c) {
    out.col(c).noalias() -= Dr * V.col(c);
    out.col(c).noalias() -= Kr * X.col(c);
  }
  return out;
}
}  // namespace

TEST(StageProducts, AreEigensRowProductsBitForBit) {
  const int n = 37;
  const SparseMatrix K = band_and_border(n, 3, 2, 5u);
  SparseMatrix Dsame = K;  // the same pattern, other values (one of them zero)
  for (int k = 0; k < Dsame.outerSize(); ++k)
    for (SparseMatrix::InnerIterator it(Dsame, k); it; ++it) it.valueRef() = 0.01 * it.value() * (it.row() % 5 == 0 ? 0.0 : 1.3);
  SparseMatrix Dzero = K;
  Dzero *= 0.0;
  const SparseMatrix Dother = band_and_border(n, 1, 0, 9u);  // a pattern of its own
  for (const SparseMatrix* D : std::vector<const SparseMatrix*>{&Dsame, &Dzero, &Dother})
    for (int cols : {1, 2, 4, 5, 9}) {
      const MatrixXd V = MatrixXd::Random(n, cols), X = MatrixXd::Random(n, cols), R = MatrixXd::Random(n, cols);
      const StageProducts p(*D, K);
      MatrixXd out(n, cols);
      p.subtract(V.data(), X.data(), R.data(), out.data(), cols);
      EXPECT_TRUE(out == eigen_products(*D, K, V, X, R)) << "columns " << cols;
      MatrixXd in_place = R;  // out may be r
      p.subtract(V.data(), X.data(), in_place.data(), in_place.data(), cols);
      EXPECT_TRUE(in_place == out);
    }
}
