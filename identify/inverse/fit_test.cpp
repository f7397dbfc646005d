#include "scoleid/identify/inverse/fit_test.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

namespace scoleid::identify {

namespace {

// A sensor's noise variance from its residual r when none is stated: second differences of the
// residual, bounded by fourth differences of the data z (noise is in the data, so a high-frequency
// misfit of a model to smooth data is not counted as noise). At least 3 samples.
double estimated_noise_variance(const Eigen::VectorXd& r, const Eigen::VectorXd& z) {
  const Eigen::Index N = r.size();
  double sum = 0.0;
  for (Eigen::Index i = 1; i + 1 < N; ++i) {
    const double d2 = r[i + 1] - 2.0 * r[i] + r[i - 1];
    sum += d2 * d2;
  }
  double var = sum / (6.0 * static_cast<double>(N - 2));
  if (N >= 5) {
    double sz = 0.0;
    for (Eigen::Index i = 2; i + 2 < N; ++i) {
      const double d4 = z[i + 2] - 4.0 * z[i + 1] + 6.0 * z[i] - 4.0 * z[i - 1] + z[i - 2];
      sz += d4 * d4;
    }
    var = std::min(var, sz / (70.0 * static_cast<double>(N - 4)));
  }
  return var;
}

// The sensor whose residual passes only on a discretisation estimate over kUnresolvedDiscretisation
// of its signal, the residual being over that too (the largest such estimate), or null.
const SensorFit* unresolved_sensor(const std::vector<SensorFit>& sensors) {
  const SensorFit* unresolved = nullptr;
  for (const auto& s : sensors)
    if (s.rms_signal > 0 && s.discretisation > kUnresolvedDiscretisation * s.rms_signal &&
        s.systematic > kUnresolvedDiscretisation * s.rms_signal &&
        (!unresolved || s.discretisation / s.rms_signal > unresolved->discretisation / unresolved->rms_signal))
      unresolved = &s;
  return unresolved;
}

// The fit test's one-line verdict: why it cannot be tested, which sensor is unresolved, which
// allowance it passes on, or the worst sensor beyond its own.
std::string fit_message(const FitTest& f, double model_error, Eigen::Index N, bool finite, bool disc, const SensorFit* unresolved) {
  std::string message;
  char buf[512];
  if (N < 3) {
    message = "fewer than 3 samples: the fit cannot be tested";
  } else if (!finite) {
    message = "the model's outputs at the estimate are not finite";
  } else if (unresolved) {
    std::snprintf(buf, sizeof buf,
                  "sensor %s's residual (%.3g %% of its RMS signal) passes only on the model's own discretisation error at this "
                  "point, %.3g %% (both over %.0f %%): its mesh and step do not resolve it, and no fit can be tested against such "
                  "an allowance (start nearer, or refine identification.elements or identification.time_step)",
                  unresolved->name.c_str(), 100.0 * unresolved->systematic / unresolved->rms_signal,
                  100.0 * unresolved->discretisation / unresolved->rms_signal, 100.0 * kUnresolvedDiscretisation);
    message = buf;
  } else {
    // The sensor furthest beyond its own allowance, to say where the misfit is.
    const SensorFit* worst = nullptr;
    auto beyond = [](const SensorFit& s) { return s.allowed > 0 ? s.systematic / s.allowed : (s.systematic > 0 ? INFINITY : 0.0); };
    for (const auto& s : f.sensors)
      if (s.rms_signal > 0 && (!worst || beyond(s) > beyond(*worst))) worst = &s;
    char dbuf[40] = "not estimated";
    if (disc && worst) std::snprintf(dbuf, sizeof dbuf, "%.3g %%", 100.0 * worst->discretisation / worst->rms_signal);
    if ((f.explains_data || !worst) && !f.within_noise_and_discretisation && model_error > 0)
      std::snprintf(buf, sizeof buf,
                    "passes only with the model-error allowance of %.3g %% (identification.model_error): the residual needs at "
                    "least %.3g %%, beyond what noise and discretisation allow",
                    100.0 * model_error, 100.0 * f.model_error_needed);
    else if (f.explains_data || !worst)
      std::snprintf(buf, sizeof buf, "the systematic residual is %.2f of what noise, discretisation and the declared model error allow",
                    f.ratio);
    else
      std::snprintf(buf, sizeof buf,
                    "the systematic residual is %.3g times what noise, discretisation and the declared model error (%.3g %%) "
                    "allow; worst sensor %s: %.3g %% of its RMS signal against %.3g %% (noise %.3g %%%s, discretisation %s)",
                    f.ratio, 100.0 * model_error, worst->name.c_str(), 100.0 * worst->systematic / worst->rms_signal,
                    100.0 * worst->allowed / worst->rms_signal, 100.0 * worst->noise / worst->rms_signal,
                    (" " + worst->noise_origin).c_str(), dbuf);
    message = buf;
  }
  return message;
}

}  // namespace

FitTest fit_test(const FitTestInputs& in) {
  const Eigen::Index N = in.residual.rows(), ns = in.residual.cols();
  if (in.data.rows() != N || in.data.cols() != ns) throw std::invalid_argument("fit_test: residual and data differ in shape");
  const bool disc = in.discretisation.size() > 0;
  if (disc && (in.discretisation.rows() != N || in.discretisation.cols() != ns))
    throw std::invalid_argument("fit_test: discretisation and residual differ in shape");
  FitTest f;
  f.model_error = in.model_error;
  // Sums over sensors of s², a² and the strict a² (without m), each relative to the sensor's mean
  // square signal, as the cost weighs them.
  double S = 0.0, A = 0.0, A_strict = 0.0, band_var = 0.0;
  int moving = 0;  // sensors with a signal
  bool finite = N >= 3;
  for (Eigen::Index k = 0; k < ns; ++k) {
    SensorFit s;
    s.name = static_cast<std::size_t>(k) < in.names.size() ? in.names[static_cast<std::size_t>(k)] : "sensor " + std::to_string(k);
    const Eigen::VectorXd r = in.residual.col(k);
    const double ms_r = r.squaredNorm() / static_cast<double>(N);
    s.rms_residual = std::sqrt(ms_r);
    s.rms_signal = std::sqrt(in.data.col(k).squaredNorm() / static_cast<double>(N));
    const double stated = static_cast<std::size_t>(k) < in.noise_std.size() ? in.noise_std[static_cast<std::size_t>(k)] : 0.0;
    double var = 0.0;
    if (stated > 0) {
      var = stated * stated;
    } else if (N >= 3) {
      var = estimated_noise_variance(r, in.data.col(k));
      s.noise_estimated = true;
    }
    const std::string origin = static_cast<std::size_t>(k) < in.noise_origin.size() ? in.noise_origin[static_cast<std::size_t>(k)] : "";
    s.noise_origin = s.noise_estimated ? "estimated" : origin == "pre-trigger" ? "from the pre-trigger" : "stated";
    s.noise = std::sqrt(var);
    s.systematic = std::sqrt(std::max(0.0, ms_r - var));
    s.discretisation = disc ? std::sqrt(in.discretisation.col(k).squaredNorm() / static_cast<double>(N)) : std::nan("");
    const double independent = std::max(1.0, in.independent_fraction * static_cast<double>(N));
    const double band2 = 3.0 * var * std::sqrt(2.0 / independent);
    const double strict2 = band2 + (disc ? 4.0 * s.discretisation * s.discretisation : 0.0);
    const double allowed2 = strict2 + std::pow(in.model_error * s.rms_signal, 2);
    s.allowed = std::sqrt(allowed2);
    s.explained = std::isfinite(ms_r) && s.systematic <= s.allowed;
    if (!std::isfinite(ms_r)) finite = false;
    // A sensor that reads nothing weighs by its noise alone (its allowance, when there is one).
    const double scale = s.rms_signal > 0 ? s.rms_signal * s.rms_signal : std::max(allowed2, 1e-300);
    S += s.systematic * s.systematic / scale;
    // The noise bands enter the sum as one χ² band: the variances of independent sensors' sample
    // variances add (2σ⁴/N each), so three standard deviations of the sum.
    band_var += std::pow(band2 / 3.0 / scale, 2);
    A += (allowed2 - band2) / scale;
    A_strict += (strict2 - band2) / scale;
    if (s.rms_signal > 0) ++moving;  // each adds m² to the allowance's sum
    f.sensors.push_back(s);
  }
  A += 3.0 * std::sqrt(band_var);
  A_strict += 3.0 * std::sqrt(band_var);
  // A residual over half a sensor's signal that passes only on a discretisation estimate over half
  // too says the model at this point is not resolved by its own mesh and step (a start or an
  // estimate far stiffer than the step was chosen for): an allowance of twice that would pass any
  // fit, so the fit is not explained. (A small residual beside a large, conservative estimate — a
  // hammer's pulse the step resolves coarsely — is a fit like any other.)
  const SensorFit* unresolved = disc ? unresolved_sensor(f.sensors) : nullptr;
  f.explains_data = finite && !unresolved && S <= A;
  f.within_noise_and_discretisation = finite && !unresolved && S <= A_strict;
  f.ratio = A > 0 ? std::sqrt(S / A) : (S > 0 ? INFINITY : 0.0);
  // The least model error with which the sum passes: S <= A_strict + moving·m².
  f.model_error_needed = S <= A_strict ? 0.0 : moving > 0 ? std::sqrt((S - A_strict) / moving) : INFINITY;
  f.message = fit_message(f, in.model_error, N, finite, disc, unresolved);
  return f;
}

}  // namespace scoleid::identify
