#include "scoleid/identify/inverse/coefficient_quadrature.h"

#include <algorithm>
#include <cstdint>
#include <cstdlib>

namespace scoleid::identify {

namespace {
std::int64_t key(int r, int s, int n) { return static_cast<std::int64_t>(r) * n + s; }
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

// The kind's pattern: the union of its coefficient-carrying terms' nonzeros. The band's half-width
// b is the widest for which the band is at least half filled by the pattern (a band sum over empty
// cells costs a vector lane; a pair outside costs an indexed multiply-add).
void CoefficientQuadrature::build(Kind& k, const std::vector<OperatorTerm>& terms, int n, double sign,
                                  const std::vector<bool>& needed) {
  const auto carried = [&](const OperatorTerm& t) {
    return t.coefficient >= 0 && (needed.empty() || needed[static_cast<std::size_t>(t.coefficient)]);
  };
  std::vector<std::int64_t> pattern;
  for (const auto& t : terms) {
    if (!carried(t)) continue;
    for (int c = 0; c < t.matrix.outerSize(); ++c)
      for (SparseMatrix::InnerIterator it(t.matrix, c); it; ++it)
        pattern.push_back(key(static_cast<int>(it.row()), static_cast<int>(it.col()), n));
  }
  if (pattern.empty()) return;
  k.used = true;
  std::sort(pattern.begin(), pattern.end());
  pattern.erase(std::unique(pattern.begin(), pattern.end()), pattern.end());
  std::vector<long> by_offset(static_cast<std::size_t>(n), 0);  // pairs with |s − r| = d
  for (std::int64_t p : pattern) ++by_offset[static_cast<std::size_t>(std::abs(p % n - p / n))];
  long inside = 0;
  for (int b = 0; b < n; ++b) {
    inside += by_offset[static_cast<std::size_t>(b)];
    const long cells = static_cast<long>(2 * b + 1) * n - static_cast<long>(b) * (b + 1);
    if (by_offset[static_cast<std::size_t>(b)] > 0 && 2 * inside >= cells) k.b = b;
  }
  k.band = Eigen::MatrixXd::Zero(n, 2 * k.b + 1);
  std::vector<int> outside_index(pattern.size(), -1);  // a pattern pair's place among those outside
  for (std::size_t i = 0; i < pattern.size(); ++i) {
    const int r = static_cast<int>(pattern[i] / n), s = static_cast<int>(pattern[i] % n);
    if (std::abs(s - r) > k.b) {
      outside_index[i] = static_cast<int>(k.row.size());
      k.row.push_back(r);
      k.col.push_back(s);
    }
  }
  k.outside = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(k.row.size()));
  for (const auto& t : terms) {
    if (!carried(t)) continue;
    for (int c = 0; c < t.matrix.outerSize(); ++c)
      for (SparseMatrix::InnerIterator it(t.matrix, c); it; ++it) {
        const int r = static_cast<int>(it.row()), s = static_cast<int>(it.col());
        int where;
        if (std::abs(s - r) <= k.b) {
          where = k.b + s - r;
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

// band(r, b + d) += wt · left_r · right_{r+d} for every r with 0 ≤ r + d < n.
void CoefficientQuadrature::accumulate(Kind& k, double wt, const Eigen::VectorXd& left, const Eigen::VectorXd& right) {
  const Eigen::Index n = left.size();
  for (int d = -k.b; d <= k.b; ++d) {
    const Eigen::Index r0 = d < 0 ? -d : 0, len = n - std::abs(d);
    k.band.col(k.b + d).segment(r0, len).array() +=
        wt * left.segment(r0, len).array() * right.segment(r0 + d, len).array();
  }
  for (std::size_t i = 0; i < k.row.size(); ++i)
    k.outside[static_cast<Eigen::Index>(i)] += wt * left[k.row[i]] * right[k.col[i]];
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
