#pragma once
// The reported uncertainty interval of each estimated parameter: noise and model error together
// (docs/theory.md §8.2).
//
// The Cramér–Rao std describes white measurement noise on a perfect model. Data from a structure
// the model does not describe exactly carry a systematic residual as well, and part of that model
// error is absorbed into the estimate where no residual shows it. The interval adds three terms,
// each an estimate of a separate source of error, with no factor fitted to any case:
//
//   half_width_i = 2·√(std_i² + resolution_i²)   noise (95 %) and the visible systematic residual
//                + |q̂_i − q̂_i^(T/2)|               the shift of a refit on the first half of the record
//                + Σ_j |∂q̂_i/∂θ_j| Δθ_j            declared uncertainties Δθ_j of fixed quantities
//                + |q̂_i − q̂_i(β/10)|               with a smoothness prior of weight β: its bias
//
//   resolution_i (identifiability.h): std_i·‖e‖_W, the change of q_i whose output effect equals
//     the residual left beyond the χ² band of the stated noise.
//   Half-record refit: model error accumulates over the record (a frequency error grows as a phase
//     error, a damping error as an amplitude error), so an estimate that still moves when the
//     record is halved is not determined to better than that move; a consistent model and white
//     noise give a shift of about one std.
//   Consider terms (Schmidt's consider analysis, as in orbit determination): a quantity the model
//     holds fixed at θ while the structure's value is θ + Δθ biases the least-squares estimate by
//     F⁻¹ Gᵀ W G_θ·Δθ (G_θ the output sensitivity to θ, central differences); only its size
//     enters the interval.
//     A mismatch that the data cannot tell from a parameter change (a reflector mass error looks
//     like a mast mass error) leaves no residual: only a declared uncertainty can cover it.
//   Smoothing shift: a smoothness prior (docs/theory.md §7.8) pulls the sections towards each
//     other by an amount the data's std does not contain (the std is the data's alone). The refit
//     with the weight lowered tenfold, from q̂, moves the estimate by about 90 % of that bias when
//     the bias is linear in β (small β); its size enters the interval.
//
// A parameter whose half-width exceeds 0.5 of its value is flagged not identifiable.
#include <string>
#include <vector>

#include "scoleid/identify/inverse/identifiability.h"

namespace scoleid::identify {

struct ConsiderTerm {
  std::string field;     // scenario field, e.g. scole.reflector.mass
  double value = 0;      // the model's value
  double delta = 0;      // its declared uncertainty (absolute)
  VectorXd shift;        // F⁻¹ Gᵀ W G_θ Δθ per estimated parameter: the bias if the structure's θ is θ + Δθ
  std::string note;      // why the shift is 0 (the outputs do not depend on θ) or NaN (no finite response); "" otherwise
};

struct IntervalInputs {
  VectorXd estimate;
  VectorXd half_record_estimate;       // empty: no refit (then the term is NaN and the interval too)
  bool half_record_converged = true;
  // false for data without a time axis (measured modes): no half-record refit applies, and the
  // interval is the noise and residual terms and the consider terms alone.
  bool refit_applies = true;
  std::vector<ConsiderTerm> consider;
  VectorXd smoothing_estimate;         // the refit at a tenth of the prior's weight; empty: no prior
  bool smoothing_converged = true;
};

struct UncertaintyInterval {
  VectorXd half_width;      // NaN where not assessed (flagged by the Fisher test, or no refit)
  VectorXd noise;           // 2·std
  VectorXd residual;        // 2·resolution
  VectorXd noise_and_residual;  // 2·√(std² + resolution²)
  VectorXd half_record_shift;   // |q̂ − q̂^(T/2)|
  VectorXd consider;            // Σ_j |shift_j|
  VectorXd smoothing_shift;     // |q̂ − q̂(β/10)|; 0 without a prior
  VectorXd half_record_delta;   // q̂ − q̂^(T/2) and q̂ − q̂(β/10), signed (empty: no refit / no prior; zero where no refit applies)
  VectorXd smoothing_delta;
  std::vector<ConsiderTerm> terms;  // the declared tolerances and their shifts
  std::vector<bool> too_wide;   // half-width > 0.5·|q̂|
  std::string note;             // why the interval is weaker than stated, "" if it is not
};

UncertaintyInterval uncertainty_interval(const Identifiability& ident, const IntervalInputs& in);

}  // namespace scoleid::identify
