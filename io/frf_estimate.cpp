#include "scoleid/io/frf_estimate.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "scoleid/io/error.h"

namespace scoleid::io {

namespace {

using cd = std::complex<double>;
constexpr double kPi = 3.14159265358979323846;
constexpr long double kPiL = 3.141592653589793238462643383279502884L;

// a·b without the library's NaN/inf recovery (a hot loop).
inline cd mul(cd a, cd b) {
  return {a.real() * b.real() - a.imag() * b.imag(), a.real() * b.imag() + a.imag() * b.real()};
}

// The forward DFT X_k = Σ_n x_n e^{−i2πkn/N} of any length N: iterative radix 2 when N is a power
// of two, else Bluestein's chirp z-transform (kn = (k² + n² − (k − n)²)/2 turns the DFT into a
// convolution with the chirp e^{iπ j²/N}, done by radix 2 of a length M ≥ 2N − 1).
class Fft {
 public:
  explicit Fft(std::size_t n) : n_(n), m_(1) {
    while (m_ < n) m_ <<= 1;
    if (m_ != n)
      while (m_ < 2 * n - 1) m_ <<= 1;
    twiddle_.resize(m_ / 2);
    for (std::size_t k = 0; k < m_ / 2; ++k) twiddle_[k] = std::polar(1.0, -2.0 * kPi * double(k) / double(m_));
    if (m_ != n) bluestein_setup();
  }

  // In place, n values.
  void forward(cd* a) {
    if (m_ == n_) return radix2(a);
    std::fill(work_.begin(), work_.end(), cd(0.0, 0.0));
    for (std::size_t j = 0; j < n_; ++j) work_[j] = mul(a[j], chirp_[j]);
    radix2(work_.data());
    for (std::size_t j = 0; j < m_; ++j) work_[j] = std::conj(mul(work_[j], filter_[j]));
    radix2(work_.data());  // the inverse transform, as conj(DFT(conj(·)))/M
    const double scale = 1.0 / double(m_);
    for (std::size_t k = 0; k < n_; ++k) a[k] = mul(std::conj(work_[k]) * scale, chirp_[k]);
  }

 private:
  void bluestein_setup() {
    chirp_.resize(n_);
    for (std::size_t j = 0; j < n_; ++j) {
      const std::uint64_t jj = (std::uint64_t(j) * j) % (2 * std::uint64_t(n_));  // e^{−iπj²/N} is 2N-periodic in j²
      chirp_[j] = std::polar(1.0, -kPi * double(jj) / double(n_));
    }
    filter_.assign(m_, cd(0.0, 0.0));
    for (std::size_t j = 0; j < n_; ++j) filter_[j] = std::conj(chirp_[j]);
    for (std::size_t j = 1; j < n_; ++j) filter_[m_ - j] = std::conj(chirp_[j]);
    radix2(filter_.data());
    work_.resize(m_);
  }

  void radix2(cd* a) const {
    for (std::size_t i = 1, j = 0; i < m_; ++i) {
      std::size_t bit = m_ >> 1;
      for (; j & bit; bit >>= 1) j ^= bit;
      j ^= bit;
      if (i < j) std::swap(a[i], a[j]);
    }
    for (std::size_t len = 2; len <= m_; len <<= 1) {
      const std::size_t half = len / 2, step = m_ / len;
      for (std::size_t i = 0; i < m_; i += len)
        for (std::size_t k = 0; k < half; ++k) {
          const cd t = mul(a[i + k + half], twiddle_[k * step]);
          a[i + k + half] = a[i + k] - t;
          a[i + k] += t;
        }
    }
  }

  std::size_t n_, m_;
  std::vector<cd> twiddle_, chirp_, filter_, work_;
};

std::string hz(double f) { return format_value(f) + " Hz"; }

void check_names(const char* what, std::size_t responses, const std::vector<std::string>& names) {
  if (names.size() != responses)
    throw std::invalid_argument(std::string(what) + ": " + std::to_string(names.size()) + " response names for " +
                                std::to_string(responses) + " responses");
}

// Throws unless every one of the n samples of every channel is finite; `offset` numbers them.
void check_finite(const char* what, const std::vector<const double*>& channels, std::size_t n, long long offset) {
  for (std::size_t c = 0; c < channels.size(); ++c) {
    if (n > 0 && !channels[c]) throw std::invalid_argument(std::string(what) + ": channel " + std::to_string(c) + " has no samples");
    for (std::size_t i = 0; i < n; ++i)
      if (!std::isfinite(channels[c][i]))
        throw std::invalid_argument(std::string(what) + ": sample " + std::to_string(offset + (long long)i) + " of " +
                                    (c == 0 ? std::string("the input") : "response " + std::to_string(c - 1)) +
                                    " is not finite (" + format_value(channels[c][i]) + ")");
  }
}

// F = 1 + 2 Σ_{r=1}^{K−1} (1 − r/K) c(r)², c(r) = Σ w[n] w[n + r·hop] / Σ w²: the variance of an
// average over K overlapping segments relative to K independent ones (white signals).
double overlap_factor(const std::vector<double>& w, std::size_t hop, int segments) {
  double w2 = 0;
  for (double v : w) w2 += v * v;
  double factor = 1.0;
  for (std::size_t r = 1; r < std::size_t(segments) && r * hop < w.size(); ++r) {
    double c = 0;
    for (std::size_t n = 0; n + r * hop < w.size(); ++n) c += w[n] * w[n + r * hop];
    c /= w2;
    factor += 2.0 * (1.0 - double(r) / segments) * c * c;
  }
  return factor;
}

}  // namespace

// ------------------------------------------------------------------------------------------------
// Welch

struct WelchFrf::State {
  int responses = 0;
  WelchOptions opt;
  std::size_t n = 0, hop = 0, k_lo = 0, k_hi = 0;  // segment, hop, kept lines k_lo..k_hi
  std::vector<double> window;
  std::vector<std::vector<double>> buffer;         // [channel][n], channel 0 the input
  std::size_t filled = 0;
  long long fed = 0;
  int segments = 0;
  Fft fft;
  std::vector<cd> z;
  std::vector<std::vector<cd>> spectrum;           // [channel][line] of the current segment
  std::vector<double> sxx;
  std::vector<std::vector<double>> syy;
  std::vector<std::vector<cd>> sxy;

  State(int r, const WelchOptions& o, std::size_t segment) : responses(r), opt(o), n(segment), fft(segment) {}
  double line(std::size_t k) const { return double(k) * opt.sample_rate / double(n); }
  void transform();
  void accumulate();
};

// The windowed transforms of the buffer's channels at the kept lines, two real channels per complex
// FFT: z = a + ib gives A_k = (Z_k + Z*_{N−k})/2, B_k = (Z_k − Z*_{N−k})/(2i).
void WelchFrf::State::transform() {
  const std::size_t channels = buffer.size();
  for (std::size_t a = 0; a < channels; a += 2) {
    const bool pair = a + 1 < channels;
    const double* xa = buffer[a].data();
    const double* xb = pair ? buffer[a + 1].data() : nullptr;
    for (std::size_t i = 0; i < n; ++i) z[i] = cd(window[i] * xa[i], pair ? window[i] * xb[i] : 0.0);
    fft.forward(z.data());
    for (std::size_t k = k_lo; k <= k_hi; ++k) {
      const cd zk = z[k], zm = std::conj(z[n - k]);
      spectrum[a][k - k_lo] = 0.5 * (zk + zm);
      if (pair) spectrum[a + 1][k - k_lo] = cd(0.0, -0.5) * (zk - zm);
    }
  }
}

void WelchFrf::State::accumulate() {
  const std::vector<cd>& x = spectrum[0];
  for (std::size_t j = 0; j < x.size(); ++j) sxx[j] += std::norm(x[j]);
  for (int s = 0; s < responses; ++s) {
    const std::vector<cd>& y = spectrum[s + 1];
    for (std::size_t j = 0; j < x.size(); ++j) {
      syy[s][j] += std::norm(y[j]);
      sxy[s][j] += mul(std::conj(x[j]), y[j]);
    }
  }
  ++segments;
}

WelchFrf::WelchFrf(int responses, WelchOptions o) {
  const char* what = "Welch FRF";
  auto fail = [&](const std::string& m) { throw std::invalid_argument(std::string(what) + ": " + m); };
  if (responses < 1) fail("needs at least one response, got " + std::to_string(responses));
  if (!(o.sample_rate > 0) || !std::isfinite(o.sample_rate)) fail("sample rate must be positive, got " + format_value(o.sample_rate));
  if (o.segment < 2) fail("segment must hold at least 2 samples, got " + std::to_string(o.segment));
  if (!(o.overlap >= 0 && o.overlap < 1)) fail("overlap must be in [0, 1), got " + format_value(o.overlap));
  const double nyquist = 0.5 * o.sample_rate, f_max = o.f_max == 0 ? nyquist : o.f_max;
  if (!(o.f_min >= 0) || !std::isfinite(o.f_min)) fail("f_min must be >= 0, got " + format_value(o.f_min));
  if (!(f_max > o.f_min && f_max <= nyquist)) fail("f_max must be in (f_min, " + hz(nyquist) + "], got " + format_value(o.f_max));
  state_ = std::make_unique<State>(responses, o, std::size_t(o.segment));
  State& s = *state_;
  const long overlapped = std::lround(o.overlap * double(o.segment));
  s.hop = std::size_t(std::max(1L, o.segment - overlapped));
  s.k_lo = 1;
  while (s.line(s.k_lo) <= o.f_min) ++s.k_lo;
  s.k_hi = s.n / 2;
  while (s.k_hi >= s.k_lo && s.line(s.k_hi) > f_max) --s.k_hi;
  if (s.k_hi < s.k_lo)
    fail("no line of a " + std::to_string(o.segment) + "-sample segment (every " + hz(o.sample_rate / double(o.segment)) +
         ") lies in (" + format_value(o.f_min) + ", " + format_value(f_max) + "] Hz");
  s.window.assign(s.n, 1.0);
  if (o.window == FrfWindow::Hann)
    for (std::size_t i = 0; i < s.n; ++i) s.window[i] = 0.5 * (1.0 - std::cos(2.0 * kPi * double(i) / double(s.n)));
  const std::size_t channels = std::size_t(responses) + 1, lines = s.k_hi - s.k_lo + 1;
  s.buffer.assign(channels, std::vector<double>(s.n));
  s.z.resize(s.n);
  s.spectrum.assign(channels, std::vector<cd>(lines));
  s.sxx.assign(lines, 0.0);
  s.syy.assign(std::size_t(responses), std::vector<double>(lines, 0.0));
  s.sxy.assign(std::size_t(responses), std::vector<cd>(lines, cd(0.0, 0.0)));
}

WelchFrf::~WelchFrf() = default;
WelchFrf::WelchFrf(WelchFrf&&) noexcept = default;
WelchFrf& WelchFrf::operator=(WelchFrf&&) noexcept = default;

void WelchFrf::add(const double* input, const std::vector<const double*>& responses, std::size_t n) {
  State& s = *state_;
  if (responses.size() != std::size_t(s.responses))
    throw std::invalid_argument("Welch FRF: " + std::to_string(responses.size()) + " response channels fed, " +
                                std::to_string(s.responses) + " expected");
  std::vector<const double*> ch{input};
  ch.insert(ch.end(), responses.begin(), responses.end());
  check_finite("Welch FRF", ch, n, s.fed);
  for (std::size_t done = 0; done < n;) {
    const std::size_t take = std::min(n - done, s.n - s.filled);
    for (std::size_t c = 0; c < ch.size(); ++c) std::copy(ch[c] + done, ch[c] + done + take, s.buffer[c].begin() + long(s.filled));
    s.filled += take;
    done += take;
    if (s.filled < s.n) continue;
    s.transform();
    s.accumulate();
    for (auto& b : s.buffer) std::copy(b.begin() + long(s.hop), b.end(), b.begin());
    s.filled = s.n - s.hop;
  }
  s.fed += (long long)n;
}

int WelchFrf::segments() const { return state_->segments; }

FrfData WelchFrf::result(const std::string& source, const std::string& input_name,
                         const std::vector<std::string>& response_names) const {
  const State& s = *state_;
  check_names("Welch FRF", std::size_t(s.responses), response_names);
  if (s.segments < 2)
    throw std::invalid_argument("Welch FRF: needs at least 2 segments of " + std::to_string(s.n) + " samples (" +
                                std::to_string(s.hop) + " apart), the record of " + std::to_string(s.fed) +
                                " samples holds " + std::to_string(s.segments));
  const bool h1 = s.opt.estimator == FrfEstimator::H1;
  const double k_eff = s.segments / overlap_factor(s.window, s.hop, s.segments);
  FrfData d;
  d.source = source;
  d.input = input_name;
  d.estimator = h1 ? "H1" : "H2";
  d.averages = s.segments;
  for (std::size_t k = s.k_lo; k <= s.k_hi; ++k) d.f_hz.push_back(s.line(k));
  for (int r = 0; r < s.responses; ++r) {
    FrfData::Channel ch;
    ch.sensor = response_names[std::size_t(r)];
    for (std::size_t j = 0; j < d.f_hz.size(); ++j) {
      const double sxx = s.sxx[j], syy = s.syy[r][j];
      const cd sxy = s.sxy[r][j];
      if (!(sxx > 0)) throw std::invalid_argument("Welch FRF: the input is zero at " + hz(d.f_hz[j]) + ": no H there");
      if (!h1 && std::norm(sxy) == 0)
        throw std::invalid_argument("Welch FRF: H2 of " + ch.sensor + " at " + hz(d.f_hz[j]) + ": the cross-spectrum is zero");
      const double residual = std::max(syy - std::norm(sxy) / sxx, std::numeric_limits<double>::epsilon() * syy);
      ch.H.push_back(h1 ? sxy / sxx : syy / std::conj(sxy));
      ch.variance.push_back(std::max(residual / ((k_eff - 1.0) * sxx), std::numeric_limits<double>::min()));
      ch.coherence.push_back(syy > 0 ? std::min(1.0, std::norm(sxy) / (sxx * syy)) : 0.0);
    }
    d.channels.push_back(std::move(ch));
  }
  return d;
}

// ------------------------------------------------------------------------------------------------
// Harmonic lines

namespace {

constexpr std::size_t kSeedEvery = 1024;

// Calls f(i, c, s) for every sample i < n with c[l] = cos 2πν_l i, s[l] = sin 2πν_l i (ν in cycles
// per sample): rotation recurrences, re-seeded from the exact phase every kSeedEvery samples.
template <class F>
void for_each_sample(std::size_t n, const std::vector<double>& nu, F&& f) {
  const std::size_t L = nu.size();
  std::vector<double> c(L), s(L), cw(L), sw(L);
  for (std::size_t l = 0; l < L; ++l) {
    cw[l] = std::cos(2.0 * kPi * nu[l]);
    sw[l] = std::sin(2.0 * kPi * nu[l]);
  }
  for (std::size_t i0 = 0; i0 < n; i0 += kSeedEvery) {
    for (std::size_t l = 0; l < L; ++l) {
      long double cycles = (long double)nu[l] * (long double)i0;
      cycles -= std::floor(cycles);
      const double phase = double(2.0L * kPiL * cycles);
      c[l] = std::cos(phase);
      s[l] = std::sin(phase);
    }
    for (std::size_t i = i0, end = std::min(n, i0 + kSeedEvery); i < end; ++i) {
      f(i, c.data(), s.data());
      for (std::size_t l = 0; l < L; ++l) {
        const double cn = c[l] * cw[l] - s[l] * sw[l];
        s[l] = s[l] * cw[l] + c[l] * sw[l];
        c[l] = cn;
      }
    }
  }
}

// Σ_{i<n} e^{i2πa i} = e^{iπa(n−1)} sin(πna)/sin(πa), a in cycles per sample.
cd exp_sum(long double a, std::size_t n) {
  a -= std::round(a);  // the sum is 1-periodic in a
  const long double half = kPiL * a, nn = (long double)n;
  if (std::fabs(nn * half) < 1e-9L) return cd(double(nn), 0.0);
  const long double d = std::sin(nn * half) / std::sin(half), phase = half * (nn - 1);
  return cd(double(d * std::cos(phase)), double(d * std::sin(phase)));
}

// Φ'Φ for the columns 1, cos ω_0 t, sin ω_0 t, cos ω_1 t, … over n samples (row-major, p = 2L + 1).
std::vector<double> normal_matrix(const std::vector<double>& nu, std::size_t n) {
  const std::size_t L = nu.size(), p = 2 * L + 1;
  std::vector<double> g(p * p);
  auto set = [&](std::size_t i, std::size_t j, double v) { g[i * p + j] = g[j * p + i] = v; };
  set(0, 0, double(n));
  for (std::size_t l = 0; l < L; ++l) {
    const cd s = exp_sum(nu[l], n);
    set(0, 1 + 2 * l, s.real());
    set(0, 2 + 2 * l, s.imag());
    for (std::size_t m = l; m < L; ++m) {
      const cd dif = exp_sum((long double)nu[l] - nu[m], n), sum = exp_sum((long double)nu[l] + nu[m], n);
      set(1 + 2 * l, 1 + 2 * m, 0.5 * (dif.real() + sum.real()));  // cos_l cos_m
      set(2 + 2 * l, 2 + 2 * m, 0.5 * (dif.real() - sum.real()));  // sin_l sin_m
      set(1 + 2 * l, 2 + 2 * m, 0.5 * (sum.imag() - dif.imag()));  // cos_l sin_m
      set(2 + 2 * l, 1 + 2 * m, 0.5 * (sum.imag() + dif.imag()));  // sin_l cos_m
    }
  }
  return g;
}

// The diagonal n, n/2, … of Φ'Φ when the columns are orthogonal: every line holds a whole number
// m_l of cycles (within 1e-9), 0 < m_l < n/2, all distinct; empty otherwise.
std::vector<double> orthogonal_diagonal(const std::vector<double>& nu, std::size_t n) {
  std::vector<double> cycles;
  for (double v : nu) {
    const long double m = (long double)v * (long double)n, whole = std::round(m);
    if (std::fabs(m - whole) > 1e-9L || whole < 1 || 2 * whole >= (long double)n) return {};
    if (!cycles.empty() && double(whole) == cycles.back()) return {};
    cycles.push_back(double(whole));
  }
  std::vector<double> diag(2 * nu.size() + 1, 0.5 * double(n));
  diag[0] = double(n);
  return diag;
}

// G = R'R in place (R upper, row-major); the index of the first column whose pivot² falls below
// 1e-10 of its diagonal (a column the others nearly make), or p when none does.
std::size_t cholesky(std::vector<double>& g, std::size_t p) {
  for (std::size_t j = 0; j < p; ++j) {
    double d = g[j * p + j];
    for (std::size_t k = 0; k < j; ++k) d -= g[k * p + j] * g[k * p + j];
    if (!(d > 1e-10 * g[j * p + j])) return j;
    const double r = std::sqrt(d);
    g[j * p + j] = r;
    for (std::size_t i = j + 1; i < p; ++i) {
      double v = g[j * p + i];
      for (std::size_t k = 0; k < j; ++k) v -= g[k * p + j] * g[k * p + i];
      g[j * p + i] = v / r;
    }
  }
  return p;
}

// R'y = b (forward) from row `from` on (b zero before it), in place.
void forward_solve(const std::vector<double>& r, std::size_t p, double* b, std::size_t from = 0) {
  for (std::size_t i = from; i < p; ++i) {
    double v = b[i];
    for (std::size_t k = from; k < i; ++k) v -= r[k * p + i] * b[k];
    b[i] = v / r[i * p + i];
  }
}

void back_solve(const std::vector<double>& r, std::size_t p, double* b) {
  for (std::size_t i = p; i-- > 0;) {
    double v = b[i];
    for (std::size_t k = i + 1; k < p; ++k) v -= r[i * p + k] * b[k];
    b[i] = v / r[i * p + i];
  }
}

// The diagonal of G⁻¹ = R⁻¹R⁻ᵀ: (G⁻¹)_jj = |y|², R'y = e_j.
std::vector<double> cholesky_inverse_diagonal(const std::vector<double>& r, std::size_t p) {
  std::vector<double> diag(p), y(p);
  for (std::size_t j = 0; j < p; ++j) {
    std::fill(y.begin(), y.end(), 0.0);
    y[j] = 1.0;
    forward_solve(r, p, y.data(), j);
    for (std::size_t i = j; i < p; ++i) diag[j] += y[i] * y[i];
  }
  return diag;
}

// One channel's fit: the complex amplitude per line and its variance E|δA|².
struct LineFit {
  std::vector<cd> A;
  std::vector<double> var;
};

void check_lines(const LinesOptions& o, std::size_t n) {
  auto fail = [](const std::string& m) { throw std::invalid_argument("harmonic FRF: " + m); };
  if (!(o.sample_rate > 0) || !std::isfinite(o.sample_rate)) fail("sample rate must be positive, got " + format_value(o.sample_rate));
  if (o.lines_hz.empty()) fail("no lines");
  const double nyquist = 0.5 * o.sample_rate;
  for (std::size_t l = 0; l < o.lines_hz.size(); ++l) {
    const double f = o.lines_hz[l];
    if (!(f > 0 && f < nyquist)) fail("line " + format_value(f) + " Hz is outside (0, " + hz(nyquist) + ") (the Nyquist frequency)");
    if (l > 0 && !(f > o.lines_hz[l - 1])) fail("lines must be strictly increasing, got " + format_value(f) + " Hz after " + hz(o.lines_hz[l - 1]));
  }
  if (n <= 2 * o.lines_hz.size() + 1)
    fail(std::to_string(o.lines_hz.size()) + " lines need more than " + std::to_string(2 * o.lines_hz.size() + 1) +
         " samples, got " + std::to_string(n));
}

// The normal equations G θ = Φ'x, solved: G's Cholesky factor, or its diagonal when the columns are
// orthogonal (the DFT shortcut: θ_j = (Φ'x)_j / G_jj).
struct Normal {
  std::size_t p = 0;
  std::vector<double> r;     // R, G = R'R (general)
  std::vector<double> diag;  // G's diagonal (orthogonal)
  void solve(double* t) const {
    if (!diag.empty()) {
      for (std::size_t j = 0; j < p; ++j) t[j] /= diag[j];
      return;
    }
    forward_solve(r, p, t);
    back_solve(r, p, t);
  }
  std::vector<double> inverse_diagonal() const {
    if (diag.empty()) return cholesky_inverse_diagonal(r, p);
    std::vector<double> inv(p);
    for (std::size_t j = 0; j < p; ++j) inv[j] = 1.0 / diag[j];
    return inv;
  }
};

Normal normal_equations(const LinesOptions& o, const std::vector<double>& nu, std::size_t n) {
  Normal eq;
  eq.p = 2 * nu.size() + 1;
  if (o.dft_when_orthogonal && (eq.diag = orthogonal_diagonal(nu, n), !eq.diag.empty())) return eq;
  eq.r = normal_matrix(nu, n);
  const std::size_t bad = cholesky(eq.r, eq.p);
  if (bad < eq.p) {
    const double f = bad == 0 ? o.lines_hz[0] : o.lines_hz[(bad - 1) / 2], record = double(n) / o.sample_rate;
    throw std::invalid_argument("harmonic FRF: the line at " + hz(f) + " cannot be told apart from the others (or from a constant) in a record of " +
                                format_value(record) + " s (its resolution is " + hz(1.0 / record) + ")");
  }
  return eq;
}

// Every channel's least-squares fit: Φ'x in one pass, θ = G⁻¹Φ'x, then the residual in another.
std::vector<LineFit> fit_lines(const std::vector<const double*>& ch, std::size_t n, const LinesOptions& o) {
  const std::size_t L = o.lines_hz.size(), p = 2 * L + 1, C = ch.size();
  std::vector<double> nu(L);
  for (std::size_t l = 0; l < L; ++l) nu[l] = o.lines_hz[l] / o.sample_rate;
  const Normal eq = normal_equations(o, nu, n);
  std::vector<std::vector<double>> theta(C, std::vector<double>(p, 0.0));
  for_each_sample(n, nu, [&](std::size_t i, const double* c, const double* s) {
    for (std::size_t k = 0; k < C; ++k) {
      const double x = ch[k][i];
      double* t = theta[k].data();
      t[0] += x;
      for (std::size_t l = 0; l < L; ++l) {
        t[1 + 2 * l] += x * c[l];
        t[2 + 2 * l] += x * s[l];
      }
    }
  });
  for (auto& t : theta) eq.solve(t.data());
  std::vector<double> rss(C, 0.0);
  for_each_sample(n, nu, [&](std::size_t i, const double* c, const double* s) {
    for (std::size_t k = 0; k < C; ++k) {
      const double* t = theta[k].data();
      double v = ch[k][i] - t[0];
      for (std::size_t l = 0; l < L; ++l) v -= t[1 + 2 * l] * c[l] + t[2 + 2 * l] * s[l];
      rss[k] += v * v;
    }
  });
  const std::vector<double> inv = eq.inverse_diagonal();
  std::vector<LineFit> fits(C);
  for (std::size_t k = 0; k < C; ++k) {
    const double sigma2 = rss[k] / double(n - p);
    for (std::size_t l = 0; l < L; ++l) {
      fits[k].A.emplace_back(theta[k][1 + 2 * l], -theta[k][2 + 2 * l]);
      fits[k].var.push_back(sigma2 * (inv[1 + 2 * l] + inv[2 + 2 * l]));
    }
  }
  return fits;
}

}  // namespace

FrfData impact_frf(const double* input, const std::vector<const double*>& responses, std::size_t n, const ImpactOptions& o,
                   const std::string& source, const std::string& input_name, const std::vector<std::string>& response_names) {
  if (!(o.sample_rate > 0) || !std::isfinite(o.sample_rate)) throw std::invalid_argument("the sample rate must be > 0");
  if (!(o.decay >= 0) || !std::isfinite(o.decay)) throw std::invalid_argument("the window's decay must be >= 0 (1/s)");
  if (n < 16) throw std::invalid_argument("an impact record needs at least 16 samples, got " + std::to_string(n));
  if (o.response_std.size() != responses.size() || response_names.size() != responses.size())
    throw std::invalid_argument("one noise level and one name per response");
  for (double s : o.response_std)
    if (!(s > 0) || !std::isfinite(s)) throw std::invalid_argument("each response's noise level must be > 0");
  if (!(o.input_std >= 0)) throw std::invalid_argument("the force's noise level must be >= 0");
  const double fs = o.sample_rate, f_max = o.f_max > 0 ? std::min(o.f_max, 0.5 * fs) : 0.5 * fs;
  std::vector<double> w(n);
  double w2 = 0.0;
  for (std::size_t i = 0; i < n; ++i) w[i] = std::exp(-o.decay * double(i) / fs), w2 += w[i] * w[i];
  Fft fft(n);
  std::vector<cd> X(n), Y(n);
  auto transform = [&](const double* x, std::vector<cd>& out) {
    for (std::size_t i = 0; i < n; ++i) {
      if (!std::isfinite(x[i])) throw std::invalid_argument("sample " + std::to_string(i + 1) + " is not finite");
      out[i] = cd(w[i] * x[i], 0.0);
    }
    fft.forward(out.data());
  };
  transform(input, X);
  FrfData d;
  d.source = source;
  d.input = input_name;
  d.estimator = "impact";
  d.averages = 1;
  d.decay = o.decay;
  const std::size_t k_hi = static_cast<std::size_t>(std::floor(f_max * double(n) / fs + 1e-9));
  for (std::size_t k = 1; k <= k_hi && k < n; ++k) d.f_hz.push_back(double(k) * fs / double(n));
  if (d.f_hz.empty()) throw std::invalid_argument("no line between 0 and " + std::to_string(f_max) + " Hz");
  for (std::size_t s = 0; s < responses.size(); ++s) {
    transform(responses[s], Y);
    FrfData::Channel ch;
    ch.sensor = response_names[s];
    for (std::size_t k = 1; k <= d.f_hz.size(); ++k) {
      const double xx = std::norm(X[k]);
      if (!(xx > 0)) throw std::invalid_argument("the force has no content at " + std::to_string(double(k) * fs / double(n)) + " Hz");
      const cd h = Y[k] / X[k];
      ch.H.push_back(h);
      ch.variance.push_back((o.response_std[s] * o.response_std[s] + std::norm(h) * o.input_std * o.input_std) * w2 / xx);
    }
    d.channels.push_back(std::move(ch));
  }
  return d;
}

double welch_effective_averages(int segments, FrfWindow window, double overlap) {
  const int N = 1024, D = static_cast<int>(std::lround((1.0 - overlap) * N));
  std::vector<double> w(N);
  for (int n = 0; n < N; ++n) w[static_cast<std::size_t>(n)] = window == FrfWindow::Hann ? 0.5 - 0.5 * std::cos(2.0 * kPi * n / N) : 1.0;
  double num = 0.0, den = 0.0;
  for (int n = 0; n < N; ++n) {
    den += w[static_cast<std::size_t>(n)] * w[static_cast<std::size_t>(n)];
    if (n + D < N) num += w[static_cast<std::size_t>(n)] * w[static_cast<std::size_t>(n + D)];
  }
  const double c = D < N ? num / den : 0.0;
  return segments / (1.0 + 2.0 * c * c);
}

FrfData harmonic_frf(const double* input, const std::vector<const double*>& responses, std::size_t n,
                     const LinesOptions& options, const std::string& source, const std::string& input_name,
                     const std::vector<std::string>& response_names) {
  check_names("harmonic FRF", responses.size(), response_names);
  if (responses.empty()) throw std::invalid_argument("harmonic FRF: needs at least one response");
  check_lines(options, n);
  std::vector<const double*> ch{input};
  ch.insert(ch.end(), responses.begin(), responses.end());
  check_finite("harmonic FRF", ch, n, 0);
  const std::vector<LineFit> fits = fit_lines(ch, n, options);
  const LineFit& x = fits[0];
  double largest = 0;
  for (const cd& a : x.A) largest = std::max(largest, std::abs(a));
  for (std::size_t l = 0; l < x.A.size(); ++l)
    if (!(std::abs(x.A[l]) >= 1e-6 * largest))
      throw std::invalid_argument("harmonic FRF: the input has no line at " + hz(options.lines_hz[l]) + " (amplitude " +
                                  format_value(std::abs(x.A[l])) + ", the largest " + format_value(largest) +
                                  "): nothing to divide by");
  FrfData d;
  d.source = source;
  d.input = input_name;
  d.estimator = "lines";
  d.f_hz = options.lines_hz;
  d.averages = int(std::floor(options.lines_hz[0] * double(n) / options.sample_rate));
  for (std::size_t k = 1; k < fits.size(); ++k) {
    FrfData::Channel c;
    c.sensor = response_names[k - 1];
    for (std::size_t l = 0; l < x.A.size(); ++l) {
      const cd h = fits[k].A[l] / x.A[l];
      c.H.push_back(h);
      const double v = (fits[k].var[l] + std::norm(h) * x.var[l]) / std::norm(x.A[l]);
      c.variance.push_back(std::max(v, std::numeric_limits<double>::min()));
    }
    d.channels.push_back(std::move(c));
  }
  return d;
}

}  // namespace scoleid::io
