#include "scoleid/identify/inverse/interval.h"

#include <cmath>
#include <string>

namespace scoleid::identify {

UncertaintyInterval uncertainty_interval(const Identifiability& id, const IntervalInputs& in) {
  const auto P = in.estimate.size();
  const double nan = std::nan("");
  UncertaintyInterval u;
  u.half_width = u.noise = u.residual = u.noise_and_residual = u.half_record_shift = u.consider =
      VectorXd::Constant(P, nan);
  const bool smoothing = in.smoothing_estimate.size() == P;
  u.smoothing_shift = smoothing ? VectorXd((in.estimate - in.smoothing_estimate).cwiseAbs()) : VectorXd::Zero(P);
  u.too_wide.assign(static_cast<std::size_t>(P), false);
  u.terms = in.consider;
  const bool refit = in.half_record_estimate.size() == P;
  if (refit) u.half_record_delta = in.estimate - in.half_record_estimate;
  if (!refit && !in.refit_applies) u.half_record_delta = VectorXd::Zero(P);  // no record to halve: the term is 0
  if (smoothing) u.smoothing_delta = in.estimate - in.smoothing_estimate;
  if (!refit && in.refit_applies) u.note = "no half-record refit: interval not assessed";
  else if (!in.half_record_converged) u.note = "the half-record refit did not converge: its shift is where it stopped";
  if (smoothing && !in.smoothing_converged)
    u.note += std::string(u.note.empty() ? "" : "; ") + "the refit at a tenth of the smoothness weight did not converge: its shift is where it stopped";
  for (const auto& t : in.consider)
    if (!t.note.empty()) u.note += std::string(u.note.empty() ? "" : "; ") + t.note;
  for (Eigen::Index i = 0; i < P; ++i) {
    double c = 0.0;
    for (const auto& t : in.consider) c += std::abs(t.shift[i]);
    u.consider[i] = c;
    if (id.std.size() != P || !std::isfinite(id.std[i])) continue;  // flagged by the Fisher test
    const double sd = id.std[i], res = std::isfinite(id.resolution[i]) ? id.resolution[i] : 0.0;
    u.noise[i] = 2.0 * sd;
    u.residual[i] = 2.0 * res;
    u.noise_and_residual[i] = 2.0 * std::hypot(sd, res);
    if (!refit && in.refit_applies) continue;
    u.half_record_shift[i] = refit ? std::abs(in.estimate[i] - in.half_record_estimate[i]) : 0.0;
    u.half_width[i] = u.noise_and_residual[i] + u.half_record_shift[i] + c + u.smoothing_shift[i];
    u.too_wide[static_cast<std::size_t>(i)] = !(u.half_width[i] <= 0.5 * std::abs(in.estimate[i]));
  }
  return u;
}

}  // namespace scoleid::identify
