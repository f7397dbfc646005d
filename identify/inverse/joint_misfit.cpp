#include "scoleid/identify/inverse/joint_misfit.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <stdexcept>

#include "scoleid/io/interrupt.h"

namespace scoleid::identify {

JointMisfit::JointMisfit(std::vector<Component> components, JointMisfitOptions options) : parts_(std::move(components)) {
  if (parts_.empty()) throw std::invalid_argument("a joint misfit needs at least one experiment");
  for (const Component& c : parts_)
    if (c.misfit == nullptr) throw std::invalid_argument("experiment '" + c.name + "' has no misfit");
  P_ = parts_.front().misfit->size();
  for (const Component& c : parts_)
    if (c.misfit->size() != P_)
      throw std::invalid_argument("experiment '" + c.name + "' does not estimate the same parameters as '" +
                                  parts_.front().name + "'");
  int hw = static_cast<int>(std::thread::hardware_concurrency());
  if (hw <= 0) hw = 1;
  threads_ = std::clamp(options.threads > 0 ? options.threads : hw, 1, static_cast<int>(parts_.size()));
  last_.assign(parts_.size(), 0.0);
  set_horizon(1.0);
  // The workers, started once; if one cannot be started, those that were are stopped and the
  // error goes to the caller.
  try {
    for (int k = 1; k < threads_; ++k) pool_.emplace_back(&JointMisfit::worker, this, k);
  } catch (...) {
    {
      std::lock_guard<std::mutex> lock(m_);
      stop_ = true;
    }
    start_.notify_all();
    for (std::thread& t : pool_) t.join();
    throw;
  }
}

JointMisfit::~JointMisfit() {
  {
    std::lock_guard<std::mutex> lock(m_);
    stop_ = true;
  }
  start_.notify_all();
  for (std::thread& t : pool_) t.join();
}

void JointMisfit::stripe(int k) {
  for (int e = k; e < components(); e += threads_) {
    try {
      (*job_)(e);
    } catch (...) {
      errors_[static_cast<std::size_t>(e)] = std::current_exception();
    }
  }
}

void JointMisfit::worker(int k) {
  long seen = 0;
  for (;;) {
    {
      std::unique_lock<std::mutex> lock(m_);
      start_.wait(lock, [&] { return stop_ || generation_ != seen; });
      if (stop_) return;
      seen = generation_;
    }
    stripe(k);
    {
      std::lock_guard<std::mutex> lock(m_);
      --pending_;
    }
    done_.notify_one();
  }
}

void JointMisfit::for_each(const std::function<void(int)>& f) {
  errors_.assign(parts_.size(), nullptr);
  job_ = &f;
  if (threads_ > 1) {
    {
      std::lock_guard<std::mutex> lock(m_);
      pending_ = threads_ - 1;
      ++generation_;
    }
    start_.notify_all();
  }
  stripe(0);
  if (threads_ > 1) {
    std::unique_lock<std::mutex> lock(m_);
    done_.wait(lock, [&] { return pending_ == 0; });
  }
  job_ = nullptr;
  // An interrupt first (it must not hide behind another experiment's failure), then the first
  // error in experiment order.
  for (const std::exception_ptr& e : errors_) {
    if (!e) continue;
    try {
      std::rethrow_exception(e);
    } catch (const io::Interrupted&) {
      throw;
    } catch (...) {
    }
  }
  for (const std::exception_ptr& e : errors_)
    if (e) std::rethrow_exception(e);
}

bool JointMisfit::timed(int e) const { return parts_[static_cast<std::size_t>(e)].misfit->has_horizon(); }

void JointMisfit::set_horizon(double s) {
  s_ = std::clamp(s, 0.0, 1.0);
  for (Component& c : parts_) {
    if (!c.misfit->has_horizon()) continue;
    const double t0 = c.misfit->data_start(), t1 = c.misfit->data_end();
    c.misfit->set_horizon(s_ >= 1.0 ? t1 : t0 + s_ * (t1 - t0));
  }
}

long JointMisfit::data_points() const {
  long n = 0;
  for (const Component& c : parts_) n += c.misfit->data_points();
  return n;
}

double JointMisfit::cost(const VectorXd& q) {
  for_each([&](int e) { last_[static_cast<std::size_t>(e)] = parts_[static_cast<std::size_t>(e)].misfit->cost(q); });
  double J = 0.0;
  for (double v : last_) J += v;
  return J;
}

double JointMisfit::cost_and_gradient(const VectorXd& q, VectorXd& gradient) {
  std::vector<VectorXd> g(parts_.size());
  for_each([&](int e) {
    const auto k = static_cast<std::size_t>(e);
    last_[k] = parts_[k].misfit->cost_and_gradient(q, g[k]);
  });
  double J = 0.0;
  gradient = VectorXd::Zero(P_);
  for (std::size_t k = 0; k < parts_.size(); ++k) {
    J += last_[k];
    gradient += g[k];
  }
  return J;
}

double JointMisfit::gauss_newton(const VectorXd& q, VectorXd& gradient, MatrixXd& H, MisfitProfile* profile) {
  std::vector<VectorXd> g(parts_.size());
  std::vector<MatrixXd> h(parts_.size());
  std::vector<MisfitProfile> prof(parts_.size());
  for_each([&](int e) {
    const auto k = static_cast<std::size_t>(e);
    last_[k] = parts_[k].misfit->gauss_newton(q, g[k], h[k], profile && timed(e) ? &prof[k] : nullptr);
  });
  double J = 0.0;
  gradient = VectorXd::Zero(P_);
  H = MatrixXd::Zero(P_, P_);
  for (std::size_t k = 0; k < parts_.size(); ++k) {
    J += last_[k];
    gradient += g[k];
    H += h[k];
  }
  if (profile) *profile = combine(prof);
  return J;
}

Misfit::MisfitProfile JointMisfit::misfit_profile(const VectorXd& q) {
  std::vector<MisfitProfile> prof(parts_.size());
  for_each([&](int e) {
    if (timed(e)) prof[static_cast<std::size_t>(e)] = parts_[static_cast<std::size_t>(e)].misfit->misfit_profile(q);
  });
  return combine(prof);
}

Misfit::MisfitProfile JointMisfit::combine(const std::vector<MisfitProfile>& profiles) const {
  // Fractions of every timed run's samples, merged; at each, the largest run misfit at or before it.
  std::vector<std::vector<double>> frac(profiles.size());
  std::vector<double> grid;
  for (std::size_t k = 0; k < profiles.size(); ++k) {
    if (!timed(static_cast<int>(k)) || profiles[k].t.empty()) continue;
    const double t0 = parts_[k].misfit->data_start(), t1 = parts_[k].misfit->data_end();
    for (double t : profiles[k].t) frac[k].push_back(t1 > t0 ? (t - t0) / (t1 - t0) : 1.0);
    grid.insert(grid.end(), frac[k].begin(), frac[k].end());
  }
  MisfitProfile out;
  if (grid.empty()) {  // modal data only: the whole data, always
    out.t = {1.0};
    out.misfit = {0.0};
    return out;
  }
  std::sort(grid.begin(), grid.end());
  grid.erase(std::unique(grid.begin(), grid.end()), grid.end());
  std::vector<std::size_t> at(profiles.size(), 0);
  for (double s : grid) {
    double worst = 0.0;
    for (std::size_t k = 0; k < profiles.size(); ++k) {
      if (frac[k].empty()) continue;
      while (at[k] + 1 < frac[k].size() && frac[k][at[k] + 1] <= s) ++at[k];
      const double m = profiles[k].misfit[at[k]];
      worst = std::isnan(m) || std::isnan(worst) ? std::nan("") : std::max(worst, m);  // NaN: within no bound
    }
    out.t.push_back(s);
    out.misfit.push_back(worst);
  }
  return out;
}

VectorXd JointMisfit::gauss_newton_product(const VectorXd& q, const VectorXd& v) {
  std::vector<VectorXd> hv(parts_.size());
  for_each([&](int e) {
    const auto k = static_cast<std::size_t>(e);
    hv[k] = parts_[k].misfit->gauss_newton_product(q, v);
  });
  VectorXd out = VectorXd::Zero(P_);
  for (const VectorXd& x : hv) out += x;
  return out;
}

bool JointMisfit::has_matrix_free_products() const {
  for (const Component& c : parts_)
    if (!c.misfit->has_matrix_free_products()) return false;
  return true;
}

}  // namespace scoleid::identify
