#pragma once
// Sampled measurements z(t_i) and their continuous interpolant z̃(t) used by the cost
//   J = ½ ∫₀ᵀ (C u − z̃)ᵀ R (C u − z̃) dt.
// z̃ is the local cubic (4-point Lagrange) interpolant of the samples: O(Δt⁴) between samples,
// so for smooth noise-free responses the interpolant adds no bias at the 1e-6 level (a linear
// interpolant would add O(Δt²)).
#include <Eigen/Dense>
#include <string>
#include <vector>

namespace scoleid::identify {

struct Measurements {
  std::vector<std::string> names;  // one per sensor (model order)
  std::vector<double> t;           // strictly increasing sample times
  Eigen::MatrixXd z;               // samples × sensors

  int sensors() const { return static_cast<int>(z.cols()); }
  // z̃(tt) into out (length sensors()); clamped beyond the ends.
  void eval(double tt, double* out) const;
  // E ∫_{t0}^{T} ñ(t)² dt for unit white noise n at the samples and ñ its interpolant: the
  // expected misfit noise adds to the cost per unit variance (≈ 0.776 (T − t0) for the cubic
  // interpolant at uniform sampling; docs/theory.md §7.8).
  double white_noise_integral(double t0, double T) const;
  // Var ∫_{t0}^{T} ñ(t)² dt for the same unit white noise: ∫ñ² = nᵀ Q n with Q_ab = ∫ w_a w_b dt
  // (w the interpolant's sample weights), so the mean is tr Q (white_noise_integral) and the
  // variance 2 Σ_ab Q_ab² — larger than the 2 Σ_a Q_aa² of independent samples, since
  // neighbouring samples share each interval.
  double white_noise_integral_variance(double t0, double T) const;
  // white_noise_integral(t.front(), t_i) at every sample time t_i, in one pass.
  std::vector<double> white_noise_integral_profile() const;
};

}  // namespace scoleid::identify
