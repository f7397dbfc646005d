#include "scoleid/io/signal.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <sstream>

namespace scoleid::io {

namespace {
constexpr double kPi = 3.14159265358979323846;

}  // namespace

double cubic_table_error(double x) {
  double e2 = 0.0;
  constexpr int n = 512;
  for (int k = 0; k < n; ++k) {
    const double mu = (k + 0.5) / n;
    const double L[4] = {-mu * (mu - 1) * (mu - 2) / 6, (mu + 1) * (mu - 1) * (mu - 2) / 2, -(mu + 1) * mu * (mu - 2) / 2,
                         (mu + 1) * mu * (mu - 1) / 6};
    std::complex<double> r = 0.0;
    for (int j = -1; j <= 2; ++j) r += L[j + 1] * std::exp(std::complex<double>(0.0, 2.0 * kPi * x * (j - mu)));
    e2 += std::norm(r - 1.0) / n;
  }
  return std::sqrt(e2);
}

double cubic_table_gain_error(double x) {
  std::complex<double> g = 0.0;
  constexpr int n = 512;  // midpoint rule in μ on a smooth integrand
  for (int k = 0; k < n; ++k) {
    const double mu = (k + 0.5) / n;
    const double L[4] = {-mu * (mu - 1) * (mu - 2) / 6, (mu + 1) * (mu - 1) * (mu - 2) / 2, -(mu + 1) * mu * (mu - 2) / 2,
                         (mu + 1) * mu * (mu - 1) / 6};
    for (int j = -1; j <= 2; ++j) g += L[j + 1] * std::exp(std::complex<double>(0.0, 2.0 * kPi * x * (j - mu)));
  }
  return std::abs(g / static_cast<double>(n) - 1.0);
}

namespace {

// The 4-point Lagrange cubic through the samples around t (the stencil shifted inside the range at
// the ends; linear below four samples), constant beyond the ends.
double cubic_table_value(const std::vector<double>& ts, const std::vector<double>& vs, double t) {
  const std::size_t N = ts.size();
  if (N < 4) return linear_table_value(ts, vs, t);
  if (t <= ts.front()) return vs.front();
  if (t >= ts.back()) return vs.back();
  const auto j = static_cast<std::size_t>(std::upper_bound(ts.begin(), ts.end(), t) - ts.begin());  // ts[j-1] <= t < ts[j]
  std::size_t s0 = j >= 2 ? j - 2 : 0;
  if (s0 + 4 > N) s0 = N - 4;
  double f = 0.0;
  for (std::size_t a = 0; a < 4; ++a) {
    double l = 1.0;
    for (std::size_t b = 0; b < 4; ++b)
      if (b != a) l *= (t - ts[s0 + b]) / (ts[s0 + a] - ts[s0 + b]);
    f += l * vs[s0 + a];
  }
  return f;
}

double term_value(const SignalTerm& s, double t) {
  using T = SignalTerm::Type;
  const double tau = t - s.t0;
  switch (s.type) {
    case T::Step: return tau >= 0.0 ? s.amplitude : 0.0;
    case T::Pulse: return (tau >= 0.0 && tau < s.width) ? s.amplitude : 0.0;
    case T::BangBang:
      if (tau < 0.0 || tau >= s.width) return 0.0;
      return tau < 0.5 * s.width ? s.amplitude : -s.amplitude;
    case T::Sine:
      if (tau < 0.0 || (s.duration > 0.0 && tau >= s.duration)) return 0.0;
      return s.amplitude * std::sin(2.0 * kPi * s.f0 * tau + s.phase);
    case T::Chirp:
      if (tau < 0.0 || tau >= s.duration) return 0.0;
      return s.amplitude *
             std::sin(2.0 * kPi * (s.f0 * tau + (s.f1 - s.f0) * tau * tau / (2.0 * s.duration)));
    case T::Haversine:
      if (tau < 0.0 || tau >= s.width) return 0.0;
      return s.amplitude * 0.5 * (1.0 - std::cos(2.0 * kPi * tau / s.width));
    case T::Table: return linear_table_value(s.times, s.values, t);
    case T::CubicTable: return cubic_table_value(s.times, s.values, t);
  }
  return 0.0;
}
}  // namespace

double linear_table_value(const std::vector<double>& ts, const std::vector<double>& vs, double t) {
  if (ts.empty()) return 0.0;
  if (t <= ts.front()) return vs.front();
  if (t >= ts.back()) return vs.back();
  const auto it = std::upper_bound(ts.begin(), ts.end(), t);
  const std::size_t k = static_cast<std::size_t>(it - ts.begin());
  const double a = (t - ts[k - 1]) / (ts[k] - ts[k - 1]);
  return (1.0 - a) * vs[k - 1] + a * vs[k];
}

Signal::Signal(std::vector<SignalTerm> terms) : terms_(std::move(terms)) {}

Signal Signal::step(double amplitude, double t0) {
  SignalTerm s;
  s.type = SignalTerm::Type::Step;
  s.amplitude = amplitude;
  s.t0 = t0;
  return Signal({s});
}

namespace {
Signal tabulated(SignalTerm::Type type, std::vector<double> times, std::vector<double> values) {
  SignalTerm s;
  s.type = type;
  s.times = std::move(times);
  s.values = std::move(values);
  return Signal({s});
}
}  // namespace

Signal Signal::cubic_table(std::vector<double> times, std::vector<double> values) {
  return tabulated(SignalTerm::Type::CubicTable, std::move(times), std::move(values));
}

Signal Signal::table(std::vector<double> times, std::vector<double> values) {
  return tabulated(SignalTerm::Type::Table, std::move(times), std::move(values));
}

double Signal::operator()(double t) const {
  double f = 0.0;
  for (const auto& s : terms_) f += term_value(s, t);
  return f;
}

std::vector<double> Signal::breakpoints() const {
  using T = SignalTerm::Type;
  std::vector<double> b;
  for (const auto& s : terms_) {
    switch (s.type) {
      case T::Step: b.push_back(s.t0); break;
      case T::Pulse:
      case T::Haversine: b.push_back(s.t0); b.push_back(s.t0 + s.width); break;
      case T::BangBang:
        b.push_back(s.t0); b.push_back(s.t0 + 0.5 * s.width); b.push_back(s.t0 + s.width);
        break;
      case T::Sine:
        b.push_back(s.t0);
        if (s.duration > 0.0) b.push_back(s.t0 + s.duration);
        break;
      case T::Chirp: b.push_back(s.t0); b.push_back(s.t0 + s.duration); break;
      case T::Table:
      case T::CubicTable: b.insert(b.end(), s.times.begin(), s.times.end()); break;
    }
  }
  std::sort(b.begin(), b.end());
  b.erase(std::unique(b.begin(), b.end()), b.end());
  return b;
}

double Signal::highest_frequency() const {
  using T = SignalTerm::Type;
  double f = 0.0;
  for (const auto& s : terms_) {
    if (s.type == T::Sine) f = std::max(f, std::abs(s.f0));
    if (s.type == T::Chirp) f = std::max({f, std::abs(s.f0), std::abs(s.f1)});
  }
  return f;
}

double Signal::shortest_width() const {
  using T = SignalTerm::Type;
  double w = std::numeric_limits<double>::infinity();
  for (const auto& s : terms_)
    if (s.type == T::Pulse || s.type == T::Haversine || s.type == T::BangBang) w = std::min(w, s.width);
  return w;
}

const char* to_string(SignalTerm::Type t) {
  using T = SignalTerm::Type;
  switch (t) {
    case T::Step: return "step";
    case T::Pulse: return "pulse";
    case T::BangBang: return "bangbang";
    case T::Sine: return "sine";
    case T::Chirp: return "chirp";
    case T::Haversine: return "haversine";
    case T::Table: return "table";
    case T::CubicTable: return "cubic-table";
  }
  return "?";
}

std::string Signal::describe() const {
  if (terms_.empty()) return "zero";
  std::ostringstream os;
  for (std::size_t i = 0; i < terms_.size(); ++i) {
    const auto& s = terms_[i];
    if (i) os << " + ";
    os << to_string(s.type);
    if (s.type == SignalTerm::Type::Table || s.type == SignalTerm::Type::CubicTable) {
      os << " (" << s.times.size() << " points)";
    } else {
      os << ' ' << s.amplitude << " at " << s.t0;
    }
  }
  return os.str();
}

}  // namespace scoleid::io
