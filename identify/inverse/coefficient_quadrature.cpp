#include "scoleid/identify/inverse/coefficient_quadrature.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>

namespace scoleid::identify {

namespace {
std::int64_t key(int r, int s, int n) { return static_cast<std::int64_t>(r) * n + s; }

// A matrix whose values differ from their transposes' by rounding at most (an assembly adds the
// same element entries in different orders): |A_rs − A_sr| ≤ 1e-13 · max |A| (an entry on one side
// only counts as its value against zero).
constexpr double kSymmetryTolerance = 1e-13;
bool symmetric_to_rounding(const SparseMatrix& A) {
  if (A.rows() != A.cols()) return false;
  const SparseMatrix D = A - SparseMatrix(A.transpose());
  double largest = 0.0, asymmetry = 0.0;
  for (int c = 0; c < A.outerSize(); ++c)
    for (SparseMatrix::InnerIterator it(A, c); it; ++it) largest = std::max(largest, std::abs(it.value()));
  for (int c = 0; c < D.outerSize(); ++c)
    for (SparseMatrix::InnerIterator it(D, c); it; ++it) asymmetry = std::max(asymmetry, std::abs(it.value()));
  return asymmetry <= kSymmetryTolerance * largest;
}
}  // namespace

CoefficientQuadrature::CoefficientQuadrature(const StructuralModel& model, bool rates, const std::vector<bool>& needed)
    : rates_(rates) {
  const int n = model.ndof;
  build(mass_, model.mass, n, rates ? 1.0 : -1.0, needed);
  build(damping_, model.damping, n, 1.0, needed);
  build(stiffness_, model.stiffness, n, 1.0, needed);
}

std::vector<bool> CoefficientQuadrature::needed_coefficients(const Eigen::MatrixXd& dcdq) {
  std::vector<bool> needed(static_cast<std::size_t>(dcdq.rows()));
  for (Eigen::Index j = 0; j < dcdq.rows(); ++j) needed[static_cast<std::size_t>(j)] = (dcdq.row(j).array() != 0.0).any();
  return needed;
}

// The kind's pattern: the union of its coefficient-carrying terms' nonzeros. A diagonal s − r = d is
// summed as a vector when the pattern fills at least 1/kDiagonalFill of it (a vector lane per
// cell against an indexed multiply-add per pair); the pairs on the other diagonals form the list.
constexpr long kDiagonalFill = 3;
void CoefficientQuadrature::build(Kind& k, const std::vector<OperatorTerm>& terms, int n, double sign,
                                  const std::vector<bool>& needed) {
  const auto carried = [&](const OperatorTerm& t) {
    return t.coefficient >= 0 && (needed.empty() || needed[static_cast<std::size_t>(t.coefficient)]);
  };
  // Every carried term symmetric (to rounding): a pair r < s is summed with its mirror,
  // left_r right_s + left_s right_r, against the term's mean value ½(A_rs + A_sr), and only the
  // upper triangle (d ≥ 0) is kept, half the cells.
  k.symmetric = true;
  for (const auto& t : terms)
    if (carried(t) && !symmetric_to_rounding(t.matrix)) k.symmetric = false;
  std::vector<SparseMatrix> upper;  // per carried term: its upper triangle (symmetric kind) or itself
  for (const auto& t : terms) {
    if (!carried(t)) {
      upper.emplace_back();
      continue;
    }
    if (!k.symmetric) {
      upper.push_back(t.matrix);
      continue;
    }
    const SparseMatrix mean = 0.5 * (t.matrix + SparseMatrix(t.matrix.transpose()));
    upper.push_back(mean.triangularView<Eigen::Upper>());
  }
  std::vector<std::int64_t> pattern;
  for (std::size_t ti = 0; ti < terms.size(); ++ti) {
    if (!carried(terms[ti])) continue;
    const SparseMatrix& A = upper[ti];
    for (int c = 0; c < A.outerSize(); ++c)
      for (SparseMatrix::InnerIterator it(A, c); it; ++it)
        pattern.push_back(key(static_cast<int>(it.row()), static_cast<int>(it.col()), n));
  }
  if (pattern.empty()) return;
  k.used = true;
  std::sort(pattern.begin(), pattern.end());
  pattern.erase(std::unique(pattern.begin(), pattern.end()), pattern.end());
  std::vector<long> by_offset(static_cast<std::size_t>(2 * n - 1), 0);  // pairs with s − r = d, at d + n − 1
  for (std::int64_t p : pattern) ++by_offset[static_cast<std::size_t>(p % n - p / n + n - 1)];
  std::vector<int> column_of(by_offset.size(), -1);  // a diagonal's column in k.band, or −1
  for (int d = 1 - n; d < n; ++d) {
    const long count = by_offset[static_cast<std::size_t>(d + n - 1)];
    if (count > 0 && kDiagonalFill * count >= n - std::abs(d)) {
      column_of[static_cast<std::size_t>(d + n - 1)] = static_cast<int>(k.offsets.size());
      k.offsets.push_back(d);
    }
  }
  const auto on_band = [&](int r, int s) { return column_of[static_cast<std::size_t>(s - r + n - 1)]; };
  k.band = Eigen::MatrixXd::Zero(n, static_cast<Eigen::Index>(k.offsets.size()));
  std::vector<int> outside_index(pattern.size(), -1);  // a pattern pair's place among those outside
  for (std::size_t i = 0; i < pattern.size(); ++i) {
    const int r = static_cast<int>(pattern[i] / n), s = static_cast<int>(pattern[i] % n);
    if (on_band(r, s) < 0) {
      outside_index[i] = static_cast<int>(k.row.size());
      k.row.push_back(r);
      k.col.push_back(s);
    }
  }
  k.outside = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(k.row.size()));
  for (std::size_t ti = 0; ti < terms.size(); ++ti) {
    const auto& t = terms[ti];
    if (!carried(t)) continue;
    const SparseMatrix& A = upper[ti];
    for (int c = 0; c < A.outerSize(); ++c)
      for (SparseMatrix::InnerIterator it(A, c); it; ++it) {
        const int r = static_cast<int>(it.row()), s = static_cast<int>(it.col());
        int where;
        if (on_band(r, s) >= 0) {
          where = on_band(r, s);
        } else {
          const auto pos = std::lower_bound(pattern.begin(), pattern.end(), key(r, s, n));
          where = -1 - outside_index[static_cast<std::size_t>(pos - pattern.begin())];
        }
        k.entries.push_back({t.coefficient, sign * it.value(), where, r});
      }
  }
}

void CoefficientQuadrature::reset() {
  for (Kind* k : {&mass_, &damping_, &stiffness_}) {
    k->band.setZero();
    k->outside.setZero();
  }
}

// band(r, column of d) += wt · left_r · right_{r+d} for every r with 0 ≤ r + d < n (a symmetric
// kind's d > 0: + wt · left_{r+d} · right_r, the mirror pair's share).
void CoefficientQuadrature::accumulate(Kind& k, double wt, const Eigen::VectorXd& left, const Eigen::VectorXd& right) {
  const int n = static_cast<int>(left.size());
  scaled_.resize(n);
  double* L = scaled_.data();
  for (int r = 0; r < n; ++r) L[r] = wt * left[r];  // (wt · left_r) · right_s, rounded as wt · left_r · right_s
  const double* R = right.data();
  for (std::size_t c = 0; c < k.offsets.size(); ++c) {
    const int d = k.offsets[c];
    double* acc = k.band.col(static_cast<Eigen::Index>(c)).data();
    if (k.symmetric && d > 0) {
      for (int r = 0; r + d < n; ++r) acc[r] += L[r] * R[r + d] + L[r + d] * R[r];
    } else {
      const int r0 = d < 0 ? -d : 0, r1 = d > 0 ? n - d : n;
      for (int r = r0; r < r1; ++r) acc[r] += L[r] * R[r + d];
    }
  }
  for (std::size_t i = 0; i < k.row.size(); ++i) {
    const int r = k.row[i], s = k.col[i];
    k.outside[static_cast<Eigen::Index>(i)] += k.symmetric && r != s ? L[r] * R[s] + L[s] * R[r] : L[r] * R[s];
  }
}

void CoefficientQuadrature::add(double wt, const Eigen::VectorXd& p, const Eigen::VectorXd& pd,
                                const Eigen::VectorXd& x, const Eigen::VectorXd& v, const Eigen::VectorXd& a) {
  if (mass_.used) {
    if (rates_)
      accumulate(mass_, wt, p, a);
    else
      accumulate(mass_, wt, pd, v);
  }
  if (damping_.used) accumulate(damping_, wt, p, v);
  if (stiffness_.used) accumulate(stiffness_, wt, p, x);
}

void CoefficientQuadrature::contract(Eigen::VectorXd& gc) const {
  for (const Kind* k : {&mass_, &damping_, &stiffness_})
    for (const auto& e : k->entries)
      gc[e.coefficient] += e.value * (e.band_col >= 0 ? k->band(e.row, e.band_col) : k->outside[-1 - e.band_col]);
}

}  // namespace scoleid::identify
