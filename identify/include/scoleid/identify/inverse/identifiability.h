#pragma once
// What the data determine, at the estimate q̂ (docs/theory.md §8; issue: "a parameter that the data
// cannot determine is flagged, not silently returned").
//
// Fisher information F = Gᵀ W G from the output sensitivities G = ∂y(t_i)/∂q at the samples,
// W = diag(1/σ_k²), σ_k the sensor's noise standard deviation (scenario or truth.json) or, when no
// noise level is known, the residual RMS of that sensor (noise_source "residual").
//   std_i = sqrt((F⁻¹)_ii): the Cramér–Rao bound for white measurement noise of that level.
//   condition number: of F scaled to relative parameters, diag(q) F diag(q).
// Resolution. A residual that is not white noise — discretisation error on noise-free synthetic
// data, the mismatch between the Simbody chain and the FE model — is not averaged away as the
// std assumes. The change of q_i whose output effect, net of what the other parameters can take
// up, equals the whole (systematic) residual is
//     resolution_i = std_i · ‖e‖_W     (‖W^½ G F⁻¹ e_i‖ = std_i),
// the shift a model error of the residual's size could cause at most (Cauchy–Schwarz on
// δq = F⁻¹ Gᵀ W e). ‖e‖_W² is the residual's χ² = Σ r²/σ² less the upper end N + 2√(2N) of the
// band white noise of the stated level stays in; with no stated level (σ from the residual) nothing can be told apart
// from noise and the whole χ² is counted. It is a limit of what the data resolve, not a bound on
// the error: at the estimate the residual is orthogonal to the sensitivities, so model error that
// mimics a parameter change (a chain's stiffness error looks like an EI change) has already been
// absorbed into the estimate and does not show in the residual at all.
// Flags: a parameter with a share > 0.1 in an eigenvector of the relative Fisher matrix whose
// eigenvalue is below 1e-12 of the largest is not identifiable; the others' std come from F
// restricted to them, and a relative std or a relative resolution above 0.5 is flagged too.
#include <string>
#include <vector>

#include "scoleid/identify/inverse/objective.h"
#include "scoleid/io/scenario.h"

namespace scoleid::identify {

struct Identifiability {
  VectorXd std;                 // per parameter (NaN when flagged by the eigenvalue test)
  VectorXd resolution;          // per parameter, change indistinguishable from the residual (NaN likewise)
  double condition_number = 0;  // of the relative Fisher matrix
  double chi2 = 0;              // Σ r²/σ² at the estimate
  long data_values = 0;         // N = samples × sensors
  std::vector<bool> identifiable;
  std::vector<std::string> reason;  // why a parameter is flagged ("" when it is not)
  std::vector<double> noise_std;  // σ_k used per sensor
  std::string noise_source;       // "scenario" | "residual" (identify_run refines "scenario" to where each level came from)
};

// `sensors` supplies each sensor's stated noise_std (<= 0: unknown).
Identifiability analyse_identifiability(Objective& objective, const std::vector<io::SensorSpec>& sensors,
                                        const VectorXd& q);

}  // namespace scoleid::identify
