#pragma once
// Does the identified model explain the data? (docs/theory.md §7.6)
//
// An optimiser stops where its own tests fire: a small step, a small gradient, a stalled cost.
// Each of them also fires at a local minimum, so "the optimiser stopped" is not "the answer is
// right". A model at the right parameters leaves a residual made of three parts only: measurement
// noise, the model's own discretisation error, and the model-form error the user expects of this
// data (a different code, a real structure). A local minimum leaves far more. The test compares,
// sensor by sensor, the systematic part of the residual with what those three parts allow:
//
//   r_k(t_i) = y_k(q̂, t_i) − z_k(t_i),  i = 1 … N (the whole record)
//   σ_k      the sensor's stated noise std, else estimated from the residual by second
//            differences, σ̂² = Σ (r_{i+1} − 2r_i + r_{i−1})² / (6 (N − 2)) — white noise passes
//            with variance 6σ², a smooth residual of angular frequency ω sampled at Δt is reduced by
//            (ωΔt)⁴ — but at most the data's own fourth-difference estimate Σ (Δ⁴z)² / (70 (N − 4)):
//            noise is in the data, so a high-frequency misfit to smooth data is not noise
//   s_k²     = mean r_k² − σ_k²: the systematic residual (mean square beyond the noise)
//   a_k²     = (χ² band, below)
//            + (2 d_k)²              d_k the RMS difference of the outputs at q̂ between the model
//                                     and the same model on twice the elements at a quarter of the
//                                     step (as the identifier's own synthetic data are made): an
//                                     estimate of the discretisation error (2: the refined model is
//                                     not exact either)
//            + (m · z_k,rms)²        m the declared model-form error, a fraction of the sensor's RMS
//                                     signal (identification.model_error)
//   explained when Σ_k s_k²/z_k,rms² <= Σ_k a_k²/z_k,rms² + 3·√(Σ_k 2σ_k⁴/(N z_k,rms⁴)), the
//   sensors weighed as the cost weighs them; the last term is three standard deviations of the
//   weighted sum of the sensors' sample variances of white noise (the χ² band). The test is on the sum, not sensor by sensor: the least-squares estimate minimises that
//   sum, so at the right parameters it is at most what it is at the true ones (the noise,
//   discretisation and model error), but it may trade one sensor's misfit for another's. The
//   per-sensor figures are reported, and the message names the sensor furthest beyond its own.
// The test is also reported without the m term (within noise and discretisation only): where the
// data allow it, that is the stricter statement, and the identifier uses it to decide whether a
// coarse-to-fine restart is worth trying.
//
// m = 0 says the data come from the model's own equations (synthetic data, analytic solutions):
// every residual beyond noise and discretisation is then a failure of the fit. Data from another
// code or a test article need m > 0; a model that fits within m is accepted, one that does not is
// reported as not explaining the data, whatever the reason — a local minimum, or a model that
// cannot describe the structure.
#include <string>
#include <vector>

#include <Eigen/Dense>

namespace scoleid::identify {

struct FitTestInputs {
  Eigen::MatrixXd residual;        // samples × sensors, model − data, over the whole record
  Eigen::MatrixXd data;            // samples × sensors
  std::vector<double> noise_std;   // per sensor, stated; <= 0 unknown (estimated)
  Eigen::MatrixXd discretisation;  // samples × sensors, refined − identifier outputs at q̂; empty = not estimated
  double model_error = 0.0;        // m, relative to each sensor's RMS signal
  std::vector<std::string> names;  // sensor names, for the message
  // Where each stated level came from ("scenario", "truth.json", "pre-trigger"), for the message;
  // empty or "" = "stated".
  std::vector<std::string> noise_origin;
  // The share of the samples that are independent (1 for white noise; g = Σh² for data filtered to
  // a band, inverse/band_filter.h): the noise's χ² band is drawn for that many values.
  double independent_fraction = 1.0;
};

struct SensorFit {
  std::string name;
  double rms_signal = 0, rms_residual = 0;
  double noise = 0;            // σ_k used
  bool noise_estimated = false;
  std::string noise_origin;    // "estimated" (from the residual), or where the level was stated
  double systematic = 0;       // s_k (RMS, >= 0)
  double discretisation = 0;   // d_k (RMS), NaN when not estimated
  double allowed = 0;          // a_k (RMS)
  bool explained = false;      // s_k <= a_k (information: the test is on the sum)
};

struct FitTest {
  bool explains_data = false;
  // The same test without the declared model error: the residual is noise and discretisation
  // only (what a correct fit of the model's own equations leaves).
  bool within_noise_and_discretisation = false;
  double ratio = 0;  // √(Σ s²/z² / Σ a²/z²): <= 1 when the data are explained
  std::vector<SensorFit> sensors;
  double model_error = 0;
  // The least model error m with which the test passes (0 when noise and discretisation suffice):
  // what a declared identification.model_error buys, stated beside it.
  double model_error_needed = 0;
  // One line: which sensor fails by how much, or that every sensor passes.
  std::string message;
  // The discretisation estimate d (samples × sensors) the test used; empty when none was made.
  Eigen::MatrixXd discretisation;
  // The model's outputs at the tested point (samples × sensors); empty when the caller did not
  // keep them (non-finite when the model could not be solved there).
  Eigen::MatrixXd predicted;
};

// A sensor whose systematic residual and discretisation estimate d_k both exceed this share of its
// RMS signal (half: a coarse net; the hammer tap tests pass with both near 12 %) makes the fit untestable (explains_data false, the message says why): the model is not
// resolved at that point, and only the allowance 2 d_k passes it.
inline constexpr double kUnresolvedDiscretisation = 0.5;

FitTest fit_test(const FitTestInputs& in);

}  // namespace scoleid::identify
