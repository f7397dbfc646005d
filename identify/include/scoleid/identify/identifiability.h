#pragma once
// What the data determine, at the estimate q̂ (DESIGN §2; issue: "a parameter that the data
// cannot determine is flagged, not silently returned").
//
// Fisher information F = Gᵀ W G from the output sensitivities G = ∂y(t_i)/∂q at the samples,
// W = diag(1/σ_k²), σ_k the sensor's noise standard deviation (scenario or truth.json) or, when no
// noise level is known, the residual RMS of that sensor (noise_source "residual").
//   std_i = sqrt((F⁻¹)_ii): the Cramér–Rao bound for white measurement noise of that level.
//   condition number: of F scaled to relative parameters, diag(q) F diag(q).
// Model-error bound. A residual that is not white noise — discretisation error on noise-free
// synthetic data, the mismatch between the Simbody chain and the FE model — biases the estimate
// instead of scattering it. If a residual e (weighted norm ‖e‖_W) were entirely systematic, the
// estimate would move by δq = F⁻¹ Gᵀ W e, whose component i is at most
//     bias_bound_i = std_i · ‖e‖_W     (Cauchy–Schwarz: ‖W^½ G F⁻¹ e_i‖ = std_i),
// reached when e lies along the part of ∂y/∂q_i the other parameters cannot take up. ‖e‖_W² is
// the residual's χ² = Σ r²/σ² less the N values white noise of the stated level accounts for; with
// no stated level (σ from the residual) nothing can be told apart from noise and the whole χ² is
// counted — the bound is then the "resolution" of q_i: the relative change whose output effect
// equals the whole residual, net of the other parameters. For noise-dominated residuals it is
// pessimistic by ~sqrt(N); for model error it is the honest size of the possible bias, where
// std_i (which assumes independent errors at every sample) can be smaller by that factor.
// Flags: a parameter with a share > 0.1 in an eigenvector of the relative Fisher matrix whose
// eigenvalue is below 1e-12 of the largest is not identifiable; the others' std come from F
// restricted to them, and a relative std or a relative model-error bound above 0.5 is flagged too.
#include <string>
#include <vector>

#include "scoleid/identify/objective.h"
#include "scoleid/io/scenario.h"

namespace scoleid::identify {

struct Identifiability {
  VectorXd std;                 // per parameter (NaN when flagged by the eigenvalue test)
  VectorXd bias_bound;          // per parameter, model-error bound (NaN likewise)
  double condition_number = 0;  // of the relative Fisher matrix
  double chi2 = 0;              // Σ r²/σ² at the estimate
  long data_values = 0;         // N = samples × sensors
  std::vector<bool> identifiable;
  std::vector<double> noise_std;  // σ_k used per sensor
  std::string noise_source;       // "scenario" | "residual"
};

// `sensors` supplies each sensor's stated noise_std (<= 0: unknown).
Identifiability analyse_identifiability(Objective& objective, const std::vector<io::SensorSpec>& sensors,
                                        const VectorXd& q);

}  // namespace scoleid::identify
