#include "scoleid/identify/time/newton_matrix.h"

#include <stdexcept>

namespace scoleid::identify {

NewtonMatrix::NewtonMatrix(const SparseMatrix& M, const SparseMatrix& D, const SparseMatrix& K, BandedCholesky::Shape shape)
    : M_(M), D_(D), K_(K), n_(static_cast<int>(M.rows())), shape_(shape) {
  cache_.reserve(kCache);  // references handed out stay valid
  if (M.nonZeros() != D.nonZeros() || M.nonZeros() != K.nonZeros())
    throw std::invalid_argument("NewtonMatrix: M, D and K must share one sparsity pattern");
  lower_slot_.assign(static_cast<std::size_t>(M.nonZeros()), -1);
  const BandedCholesky layout(n_, shape_.band, shape_.border);
  int idx = 0;
  for (int k = 0; k < M.outerSize(); ++k)
    for (SparseMatrix::InnerIterator it(M, k); it; ++it, ++idx)
      if (it.col() <= it.row()) {
        const int i = static_cast<int>(it.row()), j = static_cast<int>(it.col());
        if (!layout.fits(i, j)) throw std::invalid_argument("NewtonMatrix: entry outside band and border");
        lower_slot_[static_cast<std::size_t>(idx)] = static_cast<long>(layout.offset(i, j));
      }
}

const BandedCholesky& NewtonMatrix::factor(double gamma) {
  ++uses_;
  for (auto& e : cache_)
    if (e.last_use >= 0 && e.gamma == gamma) {
      e.last_use = uses_;
      return e.chol;
    }
  // Replace the least recently used entry (or add one).
  Entry* slot = nullptr;
  if (cache_.size() < kCache) {
    cache_.emplace_back();
    slot = &cache_.back();
    slot->chol.resize(n_, shape_);
  } else {
    slot = &cache_.front();
    for (auto& e : cache_)
      if (e.last_use < slot->last_use) slot = &e;
  }
  slot->last_use = -1;  // invalid until factored
  BandedCholesky& c = slot->chol;
  c.set_zero();
  const int nnz = static_cast<int>(M_.nonZeros());
  const double* m = M_.valuePtr();
  const double* d = D_.valuePtr();
  const double* k = K_.valuePtr();
  const double g2 = gamma * gamma;
  double* band = c.data();
  for (int i = 0; i < nnz; ++i) {
    const long s = lower_slot_[static_cast<std::size_t>(i)];
    if (s >= 0) band[s] = m[i] + gamma * d[i] + g2 * k[i];
  }
  if (!c.factorize()) throw std::runtime_error("Newton matrix M + gD + g^2 K is not positive definite");
  ++factorizations_;
  slot->gamma = gamma;
  slot->last_use = uses_;
  return c;
}

}  // namespace scoleid::identify
