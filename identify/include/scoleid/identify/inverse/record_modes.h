#pragma once
// The record's own modes: where the record places each mode when the model's form no longer ties
// it to the others (docs/theory.md §8.4).
//
// The model ties every mode's frequency and damping ratio to a few parameters (a uniform beam:
// f_n ∝ √(EI/ρA) in fixed ratios, ζ_n from ζ). A structure whose modes do not keep the model's
// ratios — a compliant clamp, a mass the model lacks, a large amplitude that stiffens one mode and
// softens another — is fitted by a compromise: each mode sits where the parameters' best balance puts
// it, and the propagated interval (modal_uncertainty.h), resting on the noise, does not see how far
// that is from where the record has it.
//
// Each mode k of the model at q̂ is freed by two directions of the operators that no parameter
// spans, in its own modal coordinate (φ_k mass-normalised, w_k = M φ_k, λ_k = ω_k²):
//
//   ∂K/∂ε_k = λ_k w_k w_kᵀ     moves λ_k to λ_k (1 + ε_k) and no other mode:  ∂f_k/∂ε_k = f_k / 2
//   ∂D/∂η_k = 2 ω_k w_k w_kᵀ   adds η_k to the modal damping ratio ζ_k:        ∂ζ_k/∂η_k = 1
//
// (Φᵀ ∂K Φ = λ_k e_k e_kᵀ by M-orthogonality, exactly; the damping's to first order.) One
// linearised least-squares step at q̂ over the kept parameters and every freed mode's (ε, η) — the
// residual r = z − y(q̂) on the output sensitivities G = [∂y/∂q, ∂y/∂ε, ∂y/∂η], weighted by the
// sensors' noise —
//
//   θ = (Gᵀ W G)⁺ Gᵀ W r,      C_θ = (g Gᵀ W G)⁺      (g the band's information scale, assessment.h)
//
// gives the record's own frequency and damping of mode k, f_k + J_f Δq + f_k ε_k / 2 and
// ζ_k + J_ζ Δq + η_k, with their std from C_θ. The pseudo-inverse (eigenvalues below 10⁻¹² of the
// largest of the column-scaled matrix dropped; by the singular values of W^½ G) keeps what is estimable: with every mode in the band
// freed, the parameters' common frequency scale is nearly spanned by the ε's, but each mode's own
// frequency is not. Only the modes in the fitted band (or below the data's Nyquist frequency) are
// freed, at most `max_modes`; one pass of P + 2m tangents. A record whose sensitivities would hold
// more than kMaxValues numbers (samples · sensors · (P + 2m); three such matrices are held at
// once) is not assessed.
#include <vector>

#include "scoleid/identify/fe/structural_model.h"
#include "scoleid/identify/inverse/objective.h"
#include "scoleid/identify/inverse/parameterization.h"

namespace scoleid::identify {

constexpr double kMaxValues = 4e7;  // 320 MB per matrix

struct RecordModesOptions {
  int max_modes = 10;          // the lowest elastic modes freed (as modal_estimates reports)
  double f_lo_hz = 0.0;        // only modes within [f_lo_hz, f_hi_hz] (the band, or the data's range)
  double f_hi_hz = 0.0;        // > 0
  double information_scale = 1.0;  // g: the band's share of the samples that are independent
};

struct RecordModes {
  // The elastic modes freed (1 = the lowest elastic mode, as ModalEstimate::mode), ascending.
  std::vector<int> modes;
  // The step θ: the parameters' (P, zero where not kept), then ε and η per freed mode.
  VectorXd dq, eps, eta;
  // The step's covariance over (q, ε_1, η_1, ε_2, η_2, …): (P + 2m) square, NaN in the rows and
  // columns of parameters not kept.
  MatrixXd covariance;
  double seconds = 0.0;          // wall time of the step (its tangents' pass included)
  int index_of(int mode) const;  // position in `modes`, −1 when not freed
};

// `Y`: the model's outputs at q (samples × sensors), the data's rows; `noise_std` per sensor (the
// Fisher step's); `kept[i]`: parameter i has a finite std. Empty when no mode lies in the range or
// the step cannot be formed.
RecordModes record_modes(Objective& obj, const StructuralModel& model, const Parameterization& params, const VectorXd& q,
                         const MatrixXd& Y, const std::vector<double>& noise_std, const std::vector<bool>& kept,
                         const RecordModesOptions& options);

}  // namespace scoleid::identify
