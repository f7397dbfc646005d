#pragma once
// The identified model's modes and their uncertainty (docs/theory.md §8.3; the record's own, §8.4).
//
// What a test engineer reports is not EI and ρA but the structure's natural frequencies f_n and
// modal damping ratios ζ_n. They are functions of the estimated parameters, m(q) (fe/state_space.h,
// modal_model: K φ = ω² M φ, ζ = φᵀ D φ / 2ω), so their uncertainty follows from the parameters' to
// first order (the delta method) with the Jacobian J = ∂m/∂q:
//
//   std(m)        = √(J C Jᵀ)                           C the Cramér–Rao covariance (identifiability.h)
//   half_width(m) = 2·√(J C Jᵀ)·√(1 + s)                 noise (95 %) and the visible systematic
//                                                        residual (resolution² = s·std², s = systematic)
//                 + |J (q̂ − q̂^(T/2))|                    the half-record refit's shift
//                 + Σ_j |J shift_j|                      the consider terms
//                 + |J (q̂ − q̂(β/10))|                    the smoothing shift
//                 + (|m_rec − m| + 2 std(m_rec))         the model's form, where |m_rec − m| > 3 std(m_rec)
//                                                        (m_rec: the record's own mode, record_modes.h)
//
// — the parameter interval's terms (interval.h), each carried through J as a vector rather than
// bounded term by term, so that correlated errors that cancel in a frequency (EI and ρA each
// uncertain, EI/ρA known) cancel here too. J by central differences of the eigenproblem at
// q̂ (1 ± 10⁻⁴) per parameter; the modes are matched by their order, so a mode whose neighbour lies
// within the perturbation's reach of it (relative gap below 10⁻³) gets no uncertainty.
//
// A mode depending on a parameter the identifiability test flagged (relative sensitivity above
// 10⁻⁸) gets none either: its std would rest on a number the data do not hold.
#include <limits>
#include <string>
#include <vector>

#include "scoleid/identify/fe/structural_model.h"
#include "scoleid/identify/inverse/interval.h"
#include "scoleid/identify/inverse/parameterization.h"
#include "scoleid/identify/inverse/record_modes.h"

namespace scoleid::identify {

struct ModalEstimate {
  int mode = 0;                    // 1 = the lowest elastic mode
  double frequency_hz = 0, damping_ratio = 0;
  // NaN where not assessed (see `note`).
  double frequency_std_hz = 0, frequency_half_width_hz = 0;
  double damping_std = 0, damping_half_width = 0;
  std::string note;                // why the uncertainty is missing, "" when it is given
  // The record's own mode (record_modes.h): its frequency and damping ratio with the mode freed
  // from the model's form, and their std (NaN where not freed). Where the record's differs from the
  // model's by more than 3 of its std, the model's form misses it: that miss plus twice the std
  // is the model-form term, added to the half-width (0 otherwise).
  double record_frequency_hz = std::numeric_limits<double>::quiet_NaN();
  double record_frequency_std_hz = std::numeric_limits<double>::quiet_NaN();
  double record_damping_ratio = std::numeric_limits<double>::quiet_NaN();
  double record_damping_std = std::numeric_limits<double>::quiet_NaN();
  double frequency_model_form_hz = 0, damping_model_form = 0;
};

struct ModalUncertaintyOptions {
  int max_modes = 10;              // the lowest elastic modes reported
  double max_frequency_hz = 0;     // > 0: only modes below it (the data's Nyquist frequency)
  double relative_step = 1e-4;     // central-difference step of each parameter
  const RecordModes* record = nullptr;  // the record's own modes (record_modes.h), if assessed
  double model_form_threshold = 3.0;    // in the record's std: a larger difference is the model's form
};

// The elastic modes (rigid-body modes, ω below rigid_floor of fe/modal.h, left out) of the model at q̂,
// lowest first, with their uncertainty from `ident` and `interval` (both may be empty: then only the
// values, and the note says why).
std::vector<ModalEstimate> modal_estimates(const StructuralModel& model, const Parameterization& params, const VectorXd& q,
                                           const Identifiability& ident, const UncertaintyInterval& interval,
                                           const ModalUncertaintyOptions& options = {});

// The correlation matrix of the estimates from the Cramér–Rao covariance (NaN in the rows and
// columns of parameters without one).
MatrixXd correlation(const Identifiability& ident);

}  // namespace scoleid::identify
