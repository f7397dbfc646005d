#include "scoleid/identify/time/stage_products.h"

#include <algorithm>
#include <cstddef>

namespace scoleid::identify {

namespace {

using RowSparse = Eigen::SparseMatrix<double, Eigen::RowMajor>;

// The shared-pattern kernel: K's indices serve D's values too; `damped` false skips D.
template <bool damped>
void subtract_products_shared(const RowSparse& D, const double* v, const RowSparse& K, const double* x, const double* r,
                              double* out, int n, int cols) {
  const int* Ko = K.outerIndexPtr();
  const int* Ki = K.innerIndexPtr();
  const double* Dv = D.valuePtr();
  const double* Kv = K.valuePtr();
  const std::ptrdiff_t ld = n;
  int c = 0;
  for (; c + 4 <= cols; c += 4) {
    const double* v0 = v + c * ld;
    const double* x0 = x + c * ld;
    const double* r0 = r + c * ld;
    double* o0 = out + c * ld;
    for (int i = 0; i < n; ++i) {
      double d0 = 0.0, d1 = 0.0, d2 = 0.0, d3 = 0.0;
      double k0 = 0.0, k1 = 0.0, k2 = 0.0, k3 = 0.0;
      for (int p = Ko[i]; p < Ko[i + 1]; ++p) {
        const int j = Ki[p];
        if constexpr (damped) {
          const double a = Dv[p];
          d0 += a * v0[j];
          d1 += a * v0[j + ld];
          d2 += a * v0[j + 2 * ld];
          d3 += a * v0[j + 3 * ld];
        }
        const double a = Kv[p];
        k0 += a * x0[j];
        k1 += a * x0[j + ld];
        k2 += a * x0[j + 2 * ld];
        k3 += a * x0[j + 3 * ld];
      }
      o0[i] = (r0[i] - d0) - k0;
      o0[i + ld] = (r0[i + ld] - d1) - k1;
      o0[i + 2 * ld] = (r0[i + 2 * ld] - d2) - k2;
      o0[i + 3 * ld] = (r0[i + 3 * ld] - d3) - k3;
    }
  }
  for (; c < cols; ++c) {
    const double* vc = v + c * ld;
    const double* xc = x + c * ld;
    const double* rc = r + c * ld;
    double* oc = out + c * ld;
    // One column: two rows at a time, their sums two independent chains.
    int i = 0;
    for (; i + 1 < n; i += 2) {
      const int p0 = Ko[i], p1 = Ko[i + 1], e1 = Ko[i + 2];
      const int common = std::min(p1 - p0, e1 - p1);
      double d0 = 0.0, k0 = 0.0, d1 = 0.0, k1 = 0.0;
      for (int m = 0; m < common; ++m) {
        const int j0 = Ki[p0 + m], j1 = Ki[p1 + m];
        if constexpr (damped) {
          d0 += Dv[p0 + m] * vc[j0];
          d1 += Dv[p1 + m] * vc[j1];
        }
        k0 += Kv[p0 + m] * xc[j0];
        k1 += Kv[p1 + m] * xc[j1];
      }
      for (int p = p0 + common; p < p1; ++p) {
        if constexpr (damped) d0 += Dv[p] * vc[Ki[p]];
        k0 += Kv[p] * xc[Ki[p]];
      }
      for (int p = p1 + common; p < e1; ++p) {
        if constexpr (damped) d1 += Dv[p] * vc[Ki[p]];
        k1 += Kv[p] * xc[Ki[p]];
      }
      oc[i] = (rc[i] - d0) - k0;
      oc[i + 1] = (rc[i + 1] - d1) - k1;
    }
    for (; i < n; ++i) {
      double d = 0.0, k = 0.0;
      for (int p = Ko[i]; p < Ko[i + 1]; ++p) {
        if constexpr (damped) d += Dv[p] * vc[Ki[p]];
        k += Kv[p] * xc[Ki[p]];
      }
      oc[i] = (rc[i] - d) - k;
    }
  }
}

}  // namespace

StageProducts::StageProducts(const SparseMatrix& D, const SparseMatrix& K) : D_(D), K_(K) {
  D_.makeCompressed();
  K_.makeCompressed();
  const auto nnz = static_cast<std::size_t>(K_.nonZeros());
  shared_pattern_ = D_.rows() == K_.rows() && D_.cols() == K_.cols() && D_.nonZeros() == K_.nonZeros() &&
                    std::equal(K_.outerIndexPtr(), K_.outerIndexPtr() + K_.rows() + 1, D_.outerIndexPtr()) &&
                    std::equal(K_.innerIndexPtr(), K_.innerIndexPtr() + nnz, D_.innerIndexPtr());
  damped_ = std::any_of(D_.valuePtr(), D_.valuePtr() + D_.nonZeros(), [](double d) { return d != 0.0; });
}

void StageProducts::subtract(const double* v, const double* x, const double* r, double* out, int cols) const {
  const int n = rows();
  if (!damped_) {
    subtract_products_shared<false>(D_, v, K_, x, r, out, n, cols);
  } else if (shared_pattern_) {
    subtract_products_shared<true>(D_, v, K_, x, r, out, n, cols);
  } else {
    // (patterns that differ: each product as Eigen forms it)
    for (int c = 0; c < cols; ++c) {
      const std::ptrdiff_t at = static_cast<std::ptrdiff_t>(c) * n;
      Eigen::Map<VectorXd> o(out + at, n);
      o = Eigen::Map<const VectorXd>(r + at, n);
      o.noalias() -= D_ * Eigen::Map<const VectorXd>(v + at, n);
      o.noalias() -= K_ * Eigen::Map<const VectorXd>(x + at, n);
    }
  }
}

}  // namespace scoleid::identify
