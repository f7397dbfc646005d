#include "scoleid/identify/time/trajectory.h"

#include <algorithm>

namespace scoleid::identify {

void Trajectory::push(double t, const double* x, const double* v, const double* a) {
  t_.push_back(t);
  X_.insert(X_.end(), x, x + n_);
  V_.insert(V_.end(), v, v + n_);
  A_.insert(A_.end(), a, a + n_);
}

namespace {
// Per-thread pool of large arrays (see the header). Bounded in entries and in bytes, so it never
// holds more than a few trajectories' worth of memory (a finished large solve is freed, not kept).
constexpr std::size_t kPoolEntries = 48;
constexpr std::size_t kPoolMinimum = 1 << 14;            // doubles; smaller arrays are not worth keeping
constexpr std::size_t kPoolDoubles = (64u << 20) / 8u;   // at most 64 MiB pooled per thread
thread_local std::vector<std::vector<double>> pool;
thread_local std::size_t pooled = 0;  // doubles held by the pool

void take(std::vector<double>& v, std::size_t need) {
  if (v.capacity() >= need) return;
  std::size_t best = pool.size();
  for (std::size_t i = 0; i < pool.size(); ++i)
    if (pool[i].capacity() >= need && (best == pool.size() || pool[i].capacity() < pool[best].capacity())) best = i;
  if (best < pool.size() && v.empty()) {
    pooled -= pool[best].capacity();
    v.swap(pool[best]);
    v.clear();
    pool[best].swap(pool.back());
    pool.pop_back();
  } else {
    v.reserve(need);
  }
}

void give(std::vector<double>& v) {
  const std::size_t c = v.capacity();
  if (c < kPoolMinimum || c > kPoolDoubles) return;
  const auto fits = [&] { return pool.size() < kPoolEntries && pooled + c <= kPoolDoubles; };
  if (!fits()) {
    // Make room by dropping smaller pooled arrays, smallest first, only if that is enough.
    std::size_t smaller = 0, count = 0;
    for (const auto& a : pool)
      if (a.capacity() < c) smaller += a.capacity(), ++count;
    if (pooled - smaller + c > kPoolDoubles || pool.size() - count >= kPoolEntries) return;
    while (!fits()) {
      auto it = std::min_element(pool.begin(), pool.end(), [](const auto& a, const auto& b) { return a.capacity() < b.capacity(); });
      pooled -= it->capacity();
      std::vector<double>().swap(*it);
      it->swap(pool.back());
      pool.pop_back();
    }
  }
  pooled += c;
  pool.emplace_back();
  pool.back().swap(v);
}
}  // namespace

Trajectory::~Trajectory() {
  give(X_);
  give(V_);
  give(A_);
}

void Trajectory::reserve(std::size_t points) {
  t_.reserve(points);
  const std::size_t need = points * static_cast<std::size_t>(n_);
  take(X_, need);
  take(V_, need);
  take(A_, need);
}

std::size_t Trajectory::locate(double t, bool right) const {
  // Index k of the interval [t_k, t_{k+1}] with t_k < t_{k+1} containing t.
  const std::size_t K = t_.size();
  std::size_t k = hint_ < K - 1 ? hint_ : 0;
  if (!(t_[k] <= t && t <= t_[k + 1] && t_[k] < t_[k + 1])) {
    const auto it = right ? std::upper_bound(t_.begin(), t_.end(), t) : std::lower_bound(t_.begin(), t_.end(), t);
    std::size_t j = static_cast<std::size_t>(it - t_.begin());
    k = j == 0 ? 0 : j - 1;
    if (k >= K - 1) k = K - 2;
    while (k + 1 < K - 1 && t_[k] == t_[k + 1]) ++k;
    while (k > 0 && t_[k] == t_[k + 1]) --k;
  } else if (right && t == t_[k + 1] && k + 2 < K) {
    k = k + 1;
    while (k + 1 < K - 1 && t_[k] == t_[k + 1]) ++k;
  }
  hint_ = k;
  return k;
}

void Trajectory::eval(double t, double* x, double* v, double* a, bool right) const {
  if (t_.size() == 1) {
    std::copy_n(X_.data(), n_, x);
    if (v) std::copy_n(V_.data(), n_, v);
    if (a) std::copy_n(A_.data(), n_, a);
    return;
  }
  t = std::clamp(t, t_.front(), t_.back());
  const std::size_t k = locate(t, right);
  const double h = t_[k + 1] - t_[k];
  const double s = h > 0 ? (t - t_[k]) / h : 0.0;
  const double s2 = s * s, s3 = s2 * s;
  const double h00 = 2 * s3 - 3 * s2 + 1, h10 = (s3 - 2 * s2 + s) * h, h01 = -2 * s3 + 3 * s2, h11 = (s3 - s2) * h;
  const double* x0 = X_.data() + k * n_;
  const double* x1 = x0 + n_;
  const double* v0 = V_.data() + k * n_;
  const double* v1 = v0 + n_;
  const double* a0 = A_.data() + k * n_;
  const double* a1 = a0 + n_;
  if (v) {
    for (int i = 0; i < n_; ++i) {
      x[i] = h00 * x0[i] + h10 * v0[i] + h01 * x1[i] + h11 * v1[i];
      v[i] = h00 * v0[i] + h10 * a0[i] + h01 * v1[i] + h11 * a1[i];
    }
  } else {
    for (int i = 0; i < n_; ++i) x[i] = h00 * x0[i] + h10 * v0[i] + h01 * x1[i] + h11 * v1[i];
  }
  if (a)
    for (int i = 0; i < n_; ++i) a[i] = (1 - s) * a0[i] + s * a1[i];
}

}  // namespace scoleid::identify
