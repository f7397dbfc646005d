#include "scoleid/identify/time/banded_cholesky.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <type_traits>

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

namespace {

// The band's full rows i ∈ [b, nb) of the two sweeps for a bandwidth B known at compile time:
// row i's entries L_{i,i−B} … L_{i,i−1} at L[i (B+1) + m], m = 0 … B−1, the diagonal's inverse in
// inv. The same operations in the same order as the generic loops (BandedCholesky::solve_in_place).
template <int B>
void band_forward(const double* L, const double* inv, double* X, int columns, std::ptrdiff_t ld, int from, int nb) {
  for (int i = from; i < nb; ++i) {
    const double* Li = L + static_cast<std::size_t>(i) * (B + 1);
    for (int j = 0; j < columns; ++j) {
      double* x = X + j * ld + (i - B);
      double s = x[B];
      for (int m = 0; m < B; ++m) s -= Li[m] * x[m];
      x[B] = s * inv[i];
    }
  }
}

template <int B>
void band_backward(const double* L, const double* inv, double* X, int columns, std::ptrdiff_t ld, int from, int nb) {
  for (int i = nb - 1; i >= from; --i) {
    const double* Li = L + static_cast<std::size_t>(i) * (B + 1);
    for (int j = 0; j < columns; ++j) {
      double* x = X + j * ld + (i - B);
      const double y = (x[B] *= inv[i]);
      for (int m = 0; m < B; ++m) x[m] -= Li[m] * y;
    }
  }
}

#if defined(__x86_64__)
// Several columns interleaved: the group's values of row i side by side (T[i·W + j], W a multiple
// of four), so that one operation of the sweep serves four columns at once (a four-wide vector;
// the compiler maps it to the machine's vector registers). Every column still sees the scalar
// sweep's operations in the scalar sweep's order — r_i, then − L_ik y_k for k ascending, then
// × 1/L_ii; in the backward sweep y_i × 1/L_ii, then − L_ik x_i into each row k above — so the
// results are bit for bit those of the one-column solve. (No fused multiply-add: a product and a
// difference each rounded, as in the scalar code: the build says -ffp-contract=off.)
typedef double Vec4 __attribute__((vector_size(32), aligned(8)));

// NV vectors (4 NV columns) per row; band rows [0, nb) hold j ∈ [max(0, i − b), i] at
// L[i (b+1) + (j − i + b)], border rows i ≥ nb hold j ∈ [0, i] at border + (i − nb) n + j. The
// band's full rows (i ≥ B) with the bandwidth B a compile-time constant; B = 0: every row generic.
template <int NV, int B>
__attribute__((target("avx"))) void solve_interleaved(const double* L, const double* inv, int n, int nb, int b, Vec4* T) {
  const int w = b + 1;
  const double* border = L + static_cast<std::size_t>(nb) * w;
  const int full_from = B > 0 ? std::min(B, nb) : nb;  // band rows [full_from, nb) through the kernel
  auto row_entries = [&](int i, int& k0) -> const double* {  // L_ik at returned[k], k ∈ [k0, i)
    if (i < nb) {
      k0 = std::max(0, i - b);
      return L + static_cast<std::size_t>(i) * w + b - i;
    }
    k0 = 0;
    return border + static_cast<std::size_t>(i - nb) * n;
  };
  auto forward_generic = [&](int i) {
    int k0 = 0;
    const double* Li = row_entries(i, k0);
    Vec4 s[NV];
    for (int v = 0; v < NV; ++v) s[v] = T[i * NV + v];
    for (int k = k0; k < i; ++k) {
      const double l = Li[k];
      for (int v = 0; v < NV; ++v) s[v] -= l * T[k * NV + v];
    }
    for (int v = 0; v < NV; ++v) T[i * NV + v] = s[v] * inv[i];
  };
  auto backward_generic = [&](int i) {
    int k0 = 0;
    const double* Li = row_entries(i, k0);
    Vec4 y[NV];
    for (int v = 0; v < NV; ++v) y[v] = T[i * NV + v] = T[i * NV + v] * inv[i];
    for (int k = k0; k < i; ++k) {
      const double l = Li[k];
      for (int v = 0; v < NV; ++v) T[k * NV + v] -= l * y[v];
    }
  };
  for (int i = 0; i < full_from; ++i) forward_generic(i);
  if constexpr (B > 0)
    for (int i = full_from; i < nb; ++i) {
      const double* Li = L + static_cast<std::size_t>(i) * (B + 1);  // L_{i,i−B+m} at Li[m]
      const Vec4* x = T + (i - B) * NV;
      Vec4 s[NV];
      for (int v = 0; v < NV; ++v) s[v] = T[i * NV + v];
      for (int m = 0; m < B; ++m)
        for (int v = 0; v < NV; ++v) s[v] -= Li[m] * x[m * NV + v];
      for (int v = 0; v < NV; ++v) T[i * NV + v] = s[v] * inv[i];
    }
  for (int i = nb; i < n; ++i) forward_generic(i);
  for (int i = n - 1; i >= nb; --i) backward_generic(i);
  if constexpr (B > 0)
    for (int i = nb - 1; i >= full_from; --i) {
      const double* Li = L + static_cast<std::size_t>(i) * (B + 1);
      Vec4* x = T + (i - B) * NV;
      Vec4 y[NV];
      for (int v = 0; v < NV; ++v) y[v] = T[i * NV + v] = T[i * NV + v] * inv[i];
      for (int m = 0; m < B; ++m)
        for (int v = 0; v < NV; ++v) x[m * NV + v] -= Li[m] * y[v];
    }
  for (int i = full_from - 1; i >= 0; --i) backward_generic(i);
}

// The group of `columns` (≤ 4 NV) columns of X: copied in four at a time, row by row (four
// sequential streams, one vector store; missing columns are zeros and stay so), solved, copied out.
template <int NV, int B>
__attribute__((target("avx"))) void solve_group(const double* L, const double* inv, int n, int nb, int b, double* X,
                                                int columns, std::ptrdiff_t ld, Vec4* T) {
  for (int g = 0; g < NV; ++g) {
    const double* x0 = X + static_cast<std::ptrdiff_t>(4 * g) * ld;
    if (4 * g + 4 <= columns) {
      const double *x1 = x0 + ld, *x2 = x1 + ld, *x3 = x2 + ld;
      for (int i = 0; i < n; ++i) T[i * NV + g] = Vec4{x0[i], x1[i], x2[i], x3[i]};
    } else {
      for (int i = 0; i < n; ++i) {
        Vec4 t{0.0, 0.0, 0.0, 0.0};
        for (int c = 0; 4 * g + c < columns; ++c) t[c] = x0[c * ld + i];
        T[i * NV + g] = t;
      }
    }
  }
  solve_interleaved<NV, B>(L, inv, n, nb, b, T);
  for (int g = 0; g < NV; ++g) {
    double* x0 = X + static_cast<std::ptrdiff_t>(4 * g) * ld;
    if (4 * g + 4 <= columns) {
      double *x1 = x0 + ld, *x2 = x1 + ld, *x3 = x2 + ld;
      for (int i = 0; i < n; ++i) {
        const Vec4 t = T[i * NV + g];
        x0[i] = t[0];
        x1[i] = t[1];
        x2[i] = t[2];
        x3[i] = t[3];
      }
    } else {
      for (int i = 0; i < n; ++i)
        for (int c = 0; 4 * g + c < columns; ++c) x0[c * ld + i] = T[i * NV + g][c];
    }
  }
}

template <int NV>
void solve_group_b(const double* L, const double* inv, int n, int nb, int b, double* X, int columns, std::ptrdiff_t ld,
                   Vec4* T) {
  switch (b) {
    case 1: solve_group<NV, 1>(L, inv, n, nb, b, X, columns, ld, T); break;
    case 2: solve_group<NV, 2>(L, inv, n, nb, b, X, columns, ld, T); break;
    case 3: solve_group<NV, 3>(L, inv, n, nb, b, X, columns, ld, T); break;
    case 4: solve_group<NV, 4>(L, inv, n, nb, b, X, columns, ld, T); break;
    case 5: solve_group<NV, 5>(L, inv, n, nb, b, X, columns, ld, T); break;
    case 6: solve_group<NV, 6>(L, inv, n, nb, b, X, columns, ld, T); break;
    case 7: solve_group<NV, 7>(L, inv, n, nb, b, X, columns, ld, T); break;
    case 8: solve_group<NV, 8>(L, inv, n, nb, b, X, columns, ld, T); break;
    default: solve_group<NV, 0>(L, inv, n, nb, b, X, columns, ld, T); break;
  }
}

#endif  // x86

// f(std::integral_constant<int, b>) for b = 1 … kMaxUnrolledBand (the callers check the range).
template <class F>
void with_bandwidth(int b, F&& f) {
  switch (b) {
    case 1: f(std::integral_constant<int, 1>{}); break;
    case 2: f(std::integral_constant<int, 2>{}); break;
    case 3: f(std::integral_constant<int, 3>{}); break;
    case 4: f(std::integral_constant<int, 4>{}); break;
    case 5: f(std::integral_constant<int, 5>{}); break;
    case 6: f(std::integral_constant<int, 6>{}); break;
    case 7: f(std::integral_constant<int, 7>{}); break;
    case 8: f(std::integral_constant<int, 8>{}); break;
    default: throw std::logic_error("BandedCholesky: no kernel for this bandwidth");
  }
}

}  // namespace

namespace {

// The scalar loops' rows (BandedCholesky::solve_in_place): columns [0, blocked) four at a time,
// the rest one at a time, every column the same operations in the same order.
// L y = r, row i of the band (entries k ∈ [k0, i)) or of the border (k ∈ [0, i)) at Li[k].
void scalar_forward_row(double* X, int columns, std::ptrdiff_t ld, const double* inv, int i, int k0, const double* Li) {
  const int blocked = columns - columns % 4;
  auto col = [X, ld](int j) { return X + static_cast<std::ptrdiff_t>(j) * ld; };
  for (int j = 0; j < blocked; j += 4) {
    double *x0 = col(j), *x1 = x0 + ld, *x2 = x1 + ld, *x3 = x2 + ld;
    double s0 = x0[i], s1 = x1[i], s2 = x2[i], s3 = x3[i];
    for (int k = k0; k < i; ++k) {
      const double l = Li[k];
      s0 -= l * x0[k];
      s1 -= l * x1[k];
      s2 -= l * x2[k];
      s3 -= l * x3[k];
    }
    x0[i] = s0 * inv[i];
    x1[i] = s1 * inv[i];
    x2[i] = s2 * inv[i];
    x3[i] = s3 * inv[i];
  }
  for (int j = blocked; j < columns; ++j) {
    double* x = col(j);
    double s = x[i];
    for (int k = k0; k < i; ++k) s -= Li[k] * x[k];
    x[i] = s * inv[i];
  }
}

// Lᵀ x = y, row i's entries k ∈ [k0, i) at Li[k] taken out of the rows above it.
void scalar_backward_row(double* X, int columns, std::ptrdiff_t ld, const double* inv, int i, int k0, const double* Li) {
  const int blocked = columns - columns % 4;
  auto col = [X, ld](int j) { return X + static_cast<std::ptrdiff_t>(j) * ld; };
  for (int j = 0; j < blocked; j += 4) {
    double *x0 = col(j), *x1 = x0 + ld, *x2 = x1 + ld, *x3 = x2 + ld;
    const double y0 = (x0[i] *= inv[i]), y1 = (x1[i] *= inv[i]), y2 = (x2[i] *= inv[i]), y3 = (x3[i] *= inv[i]);
    for (int k = k0; k < i; ++k) {
      const double l = Li[k];
      x0[k] -= l * y0;
      x1[k] -= l * y1;
      x2[k] -= l * y2;
      x3[k] -= l * y3;
    }
  }
  for (int j = blocked; j < columns; ++j) {
    double* x = col(j);
    const double xi = (x[i] *= inv[i]);
    for (int k = k0; k < i; ++k) x[k] -= Li[k] * xi;
  }
}

}  // namespace

void BandedCholesky::solve_in_place(double* x) const { solve_in_place(x, 1, n_); }

void BandedCholesky::solve_in_place(double* X, int columns, std::ptrdiff_t ld, Kernel kernel) const {
  if (columns <= 0) return;
  if (columns > 1 && ld < n_) throw std::invalid_argument("BandedCholesky::solve_in_place: leading dimension below n");
  if (inv_diag_.size() != static_cast<std::size_t>(n_)) throw std::logic_error("BandedCholesky: solve before a successful factorize");
  // Many columns go in groups: a group's rows near row i stay in the first-level cache. The groups
  // share the columns' fours (vectors of the interleaved kernel) as evenly as they can: 33 columns
  // (9 fours) go as 12 + 12 + 9, 49 (13 fours) as 16 + 12 + 12 + 9, never with a lone column.
  if (columns > kColumnGroup) {
    const int fours = (columns + 3) / 4, groups = (fours + kColumnGroup / 4 - 1) / (kColumnGroup / 4);
    for (int g = 0, j = 0; g < groups && j < columns; ++g) {
      const int size = std::min(4 * (fours / groups + (g < fours % groups ? 1 : 0)), columns - j);
      solve_in_place(X + static_cast<std::ptrdiff_t>(j) * ld, size, ld, kernel);
      j += size;
    }
    return;
  }
#if defined(__x86_64__)
  static const bool vectors = __builtin_cpu_supports("avx");  // (the interleaved kernel's instructions)
  if (kernel == Kernel::Automatic && vectors) {
    // Interleaved (solve_group above): copied in, solved four columns to an operation, copied out.
    const int NV = (columns + 3) / 4;
    thread_local std::vector<double> buffer;  // the group's rows, four doubles to a vector
    buffer.resize(static_cast<std::size_t>(n_) * NV * 4);
    Vec4* T = reinterpret_cast<Vec4*>(buffer.data());
    const double* L = data_.data();
    const double* inv = inv_diag_.data();
    switch (NV) {
      case 1: solve_group_b<1>(L, inv, n_, nb_, b_, X, columns, ld, T); break;
      case 2: solve_group_b<2>(L, inv, n_, nb_, b_, X, columns, ld, T); break;
      case 3: solve_group_b<3>(L, inv, n_, nb_, b_, X, columns, ld, T); break;
      default: solve_group_b<4>(L, inv, n_, nb_, b_, X, columns, ld, T); break;
    }
    return;
  }
#endif
  // The scalar loops. Both sweeps read L by rows, which are contiguous in storage: L y = r by dot
  // products with row i, Lᵀ x = y by axpys with row i (column-oriented back substitution). Each
  // row is applied to every column before the next row: one column is a chain of dependent
  // operations (row i needs row i − 1), several columns are independent chains the processor
  // overlaps. The band's full rows (i ≥ b) go through loops with the bandwidth a compile-time
  // constant (b ≤ 8: no loop control inside a row); the first b rows, the border rows and wider
  // bands through the generic loops, four columns at a time (one load of each entry of L for
  // four), the remainder one at a time. Every column sees the same operations in the same order,
  // so a column's result does not depend on how many are solved together, nor on which loop (or
  // kernel) solved it.
  const int w = b_ + 1;
  const double* L = data_.data();
  const double* inv = inv_diag_.data();
  auto forward_row = [&](int i, int k0, const double* Li) { scalar_forward_row(X, columns, ld, inv, i, k0, Li); };
  auto backward_row = [&](int i, int k0, const double* Li) { scalar_backward_row(X, columns, ld, inv, i, k0, Li); };
  auto band_row = [&](int i, int k0) { return L + static_cast<std::size_t>(i) * w + (k0 - i + b_) - k0; };
  // The band's first b rows (shorter than b) and, for a bandwidth without a kernel of its own, all.
  const int full_from = b_ >= 1 && b_ <= kMaxUnrolledBand ? std::min(b_, nb_) : nb_;
  for (int i = 0; i < full_from; ++i) forward_row(i, std::max(0, i - b_), band_row(i, std::max(0, i - b_)));
  if (full_from < nb_)
    with_bandwidth(b_, [&](auto B) { band_forward<decltype(B)::value>(L, inv, X, columns, ld, full_from, nb_); });
  for (int i = nb_; i < n_; ++i) forward_row(i, 0, L + offset(i, 0));
  for (int i = n_ - 1; i >= nb_; --i) backward_row(i, 0, L + offset(i, 0));
  if (full_from < nb_)
    with_bandwidth(b_, [&](auto B) { band_backward<decltype(B)::value>(L, inv, X, columns, ld, full_from, nb_); });
  for (int i = full_from - 1; i >= 0; --i) backward_row(i, std::max(0, i - b_), band_row(i, std::max(0, i - b_)));
}


}  // namespace scoleid::identify
