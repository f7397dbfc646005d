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

// The lowest harmonic k0 of a multisine (signal.h) and its lines' complex amplitudes a e^{iφ_k}.
long multisine_first(const SignalTerm& s) { return std::max(1L, static_cast<long>(std::ceil(s.f0 * s.width - 1e-9))); }
std::vector<std::complex<double>> multisine_amplitudes(const SignalTerm& s) {
  std::vector<std::complex<double>> c;
  if (!(s.width > 0.0)) return c;
  const long k0 = multisine_first(s), k1 = static_cast<long>(std::floor(s.f1 * s.width + 1e-9));
  if (k1 < k0) return c;
  const double K = static_cast<double>(k1 - k0 + 1), a = s.amplitude * std::sqrt(2.0 / K);
  for (long k = k0; k <= k1; ++k) {
    const double rank = static_cast<double>(k - k0 + 1), phi = -kPi * rank * (rank - 1.0) / K;
    c.emplace_back(a * std::cos(phi), a * std::sin(phi));
  }
  return c;
}
// Σ_k Re(c_k z^k), z = e^{i2πτ/T}: z^{k0} times the Horner sum of the amplitudes.
double multisine_value(const SignalTerm& s, const std::vector<std::complex<double>>& c, double tau) {
  if (tau < 0.0 || (s.duration > 0.0 && tau >= s.duration) || c.empty()) return 0.0;
  const double theta = 2.0 * kPi * std::fmod(tau, s.width) / s.width;
  const std::complex<double> z(std::cos(theta), std::sin(theta));
  std::complex<double> h(0.0, 0.0);
  for (auto it = c.rbegin(); it != c.rend(); ++it) h = h * z + *it;
  const double t0 = theta * static_cast<double>(multisine_first(s));
  return (h * std::complex<double>(std::cos(t0), std::sin(t0))).real();
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
    case T::Multisine: return multisine_value(s, multisine_amplitudes(s), tau);  // Signal::operator() uses its cache
  }
  return 0.0;
}
}  // namespace

std::vector<double> multisine_lines(const SignalTerm& s) {
  std::vector<double> f;
  if (!(s.width > 0.0)) return f;
  const long k0 = std::max(1L, static_cast<long>(std::ceil(s.f0 * s.width - 1e-9)));
  const long k1 = static_cast<long>(std::floor(s.f1 * s.width + 1e-9));
  for (long k = k0; k <= k1; ++k) f.push_back(static_cast<double>(k) / s.width);
  return f;
}

double linear_table_value(const std::vector<double>& ts, const std::vector<double>& vs, double t) {
  if (ts.empty()) return 0.0;
  if (t <= ts.front()) return vs.front();
  if (t >= ts.back()) return vs.back();
  const auto it = std::upper_bound(ts.begin(), ts.end(), t);
  const std::size_t k = static_cast<std::size_t>(it - ts.begin());
  const double a = (t - ts[k - 1]) / (ts[k] - ts[k - 1]);
  return (1.0 - a) * vs[k - 1] + a * vs[k];
}

Signal::Signal(std::vector<SignalTerm> terms) : terms_(std::move(terms)) {
  for (const auto& s : terms_)
    multisine_.push_back(s.type == SignalTerm::Type::Multisine ? multisine_amplitudes(s) : std::vector<std::complex<double>>{});
}

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
  for (std::size_t i = 0; i < terms_.size(); ++i)
    f += terms_[i].type == SignalTerm::Type::Multisine ? multisine_value(terms_[i], multisine_[i], t - terms_[i].t0) : term_value(terms_[i], t);
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
      case T::Multisine:
        b.push_back(s.t0);
        if (s.duration > 0.0) b.push_back(s.t0 + s.duration);
        break;
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
    if (s.type == T::Multisine && !multisine_lines(s).empty()) f = std::max(f, multisine_lines(s).back());
  }
  return f;
}

std::vector<double> Signal::lines(bool* only_lines) const {
  using T = SignalTerm::Type;
  std::vector<double> f;
  bool only = !terms_.empty();
  for (const auto& s : terms_) {
    if (s.type == T::Sine) f.push_back(s.f0);
    else if (s.type == T::Multisine) for (double x : multisine_lines(s)) f.push_back(x);
    else only = false;
  }
  std::sort(f.begin(), f.end());
  f.erase(std::unique(f.begin(), f.end()), f.end());
  if (only_lines) *only_lines = only;
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
    case T::Multisine: return "multisine";
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
