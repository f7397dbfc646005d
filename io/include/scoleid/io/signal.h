#pragma once
// Scalar time functions f(t) that drive the structures: step, pulse, bang-bang, sine, chirp,
// tabulated (piecewise linear), and sums of these. Shared by the truth generator and the
// identifier so that both apply bit-identical inputs.
//
// Conventions (consistent units, time in seconds):
//   step      f = A                      for t >= t0, else 0           (a step "at t0+")
//   pulse     f = A                      for t0 <= t < t0 + width
//   bangbang  f = +A on [t0, t0+w/2), -A on [t0+w/2, t0+w), 0 elsewhere (rest-to-rest slew)
//   sine      f = A sin(2π f0 (t - t0) + φ)  on [t0, t0+duration)   (duration <= 0: forever)
//   chirp     f = A sin(2π (f0 τ + (f1 - f0) τ² / (2 D))), τ = t - t0 in [0, D)  (linear sweep)
//   haversine f = A (1 - cos(2π (t - t0)/w)) / 2 on [t0, t0+w)   (smooth pulse)
//   multisine f = Σ_k a cos(2π k (t - t0)/T + φ_k) on [t0, t0+duration) (duration <= 0: forever):
//             the harmonics k of the period T = width whose frequencies k/T lie in [f0, f1], K of
//             them, of equal amplitude a = A √(2/K) (A the signal's RMS) and Schroeder's phases
//             φ_k = −π k'(k'−1)/K (k' = 1…K their rank), which keep the crest factor low; periodic
//             in T, so a record of whole periods in steady state holds every line without leakage
//   table     piecewise linear through (t_k, f_k), constant beyond the ends
//   cubic-table  the 4-point Lagrange cubic through the samples around t (a band-limited input's
//             reading; built in code, not from a scenario), constant beyond the ends
// Discontinuities (in f or its derivative) are exposed by breakpoints() so integrators can stop
// there instead of stepping across them.
#include <complex>
#include <string>
#include <vector>


namespace scoleid::io {

// A cubic-table's fidelity to what it was sampled from: a complex exponential of x = f·Δt cycles
// per sample, read through the table, holds the component G(x) e^{i2πxt/Δt} with
//   G(x) = ∫₀¹ Σ_{j=-1..2} L_j(μ) e^{i2πx(j−μ)} dμ,
// L_j the Lagrange basis through the nodes −1, 0, 1, 2 (the table's reading between samples 0 and 1
// at μ). Returns |G(x) − 1|: 0.25 % at x = 0.104, 1 % at 0.146, 5.4 % at 0.23 (real; G has no phase).
double cubic_table_gain_error(double x);
// The whole of the reading's error on that exponential, relative RMS over a sample interval:
//   E(x)² = ∫₀¹ |Σ_j L_j(μ) e^{i2πx(j−μ)} − 1|² dμ
// — the gain's share and the images at the sample rate's multiples ± f, which a model with modes
// there answers and its sampled output folds back onto f: 0.25 % at x = 0.0996, 0.5 % at 0.119,
// 1 % at 0.142, 6.2 % at 0.23.
double cubic_table_error(double x);

struct SignalTerm {
  enum class Type { Step, Pulse, BangBang, Sine, Chirp, Haversine, Table, CubicTable, Multisine };
  Type type = Type::Step;
  double amplitude = 0.0;
  double t0 = 0.0;
  double width = 0.0;      // pulse, bangbang, haversine; a multisine's period
  double f0 = 0.0;         // sine frequency, chirp start frequency [Hz]
  double f1 = 0.0;         // chirp end frequency [Hz]
  double duration = 0.0;   // sine, chirp
  double phase = 0.0;      // sine [rad]
  std::vector<double> times, values;  // table
};

class Signal {
public:
  Signal() = default;
  explicit Signal(std::vector<SignalTerm> terms);
  static Signal step(double amplitude, double t0 = 0.0);
  static Signal table(std::vector<double> times, std::vector<double> values);
  static Signal cubic_table(std::vector<double> times, std::vector<double> values);

  double operator()(double t) const;
  // Sorted, unique times where f or f' jumps.
  std::vector<double> breakpoints() const;
  // What a time grid must resolve: the highest frequency of a sine or chirp term (Hz; 0 = none),
  // and the shortest width of a pulse, haversine or bang-bang term (s; +inf = none).
  double highest_frequency() const;
  // The frequencies of its sine terms and multisine lines, ascending (Hz); empty when it has none.
  // `only_lines`: set to whether every term is a sine or a multisine (the signal is its lines).
  std::vector<double> lines(bool* only_lines = nullptr) const;
  double shortest_width() const;
  bool is_zero() const { return terms_.empty(); }
  const std::vector<SignalTerm>& terms() const { return terms_; }
  // One-line human description, e.g. "step 10 at 0".
  std::string describe() const;

private:
  std::vector<SignalTerm> terms_;
  // Per term, a multisine's complex line amplitudes a e^{iφ_k} (lowest first), so that the sum is
  // one Horner pass in e^{i2πτ/T}; empty for other terms.
  std::vector<std::vector<std::complex<double>>> multisine_;
};

const char* to_string(SignalTerm::Type t);
// A multisine term's line frequencies k/T in [f0, f1] (Hz, ascending; k >= 1).
std::vector<double> multisine_lines(const SignalTerm& s);

// Piecewise-linear interpolation of the samples (ts, vs) at t (ts increasing), constant beyond the
// ends; 0 without samples. A `table` signal's law and DataTable::interpolate.
double linear_table_value(const std::vector<double>& ts, const std::vector<double>& vs, double t);

}  // namespace scoleid::io
