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
#include <cmath>
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
  // The Cramér–Rao covariance of the parameters the Fisher test kept (P × P; NaN in the rows and
  // columns of the others), and the systematic share of χ² (resolution² = systematic · std²).
  MatrixXd covariance;
  // Where the Fisher matrix has directions the data cannot see (eigenvalues below 1e-12 of the
  // largest, in log q): those directions (P × k, unit columns in log q) and the pseudo-inverse's
  // covariance (P × P, in q's units). A quantity whose log-q gradient is orthogonal to every unseen
  // direction (a free decay's frequencies: EI/rho_A) has the variance gᵀ C⁺ g. Empty when there is none.
  MatrixXd unseen;
  MatrixXd covariance_pinv;
  double systematic = 0;
  std::vector<double> noise_std;  // σ_k used per sensor
  std::string noise_source;       // "scenario" | "residual" (identify_run refines "scenario" to where each level came from)
  // χ² of the sections' profile reversed end for end minus the estimate's (identify_run's mirror
  // test, docs/theory.md §8.1); NaN when not computed (no sections, or the estimate its own mirror).
  double mirror_chi2_difference = std::nan("");
  // χ² of the closest other converged attempt minus the estimate's (identify_run's other-minimum
  // test); NaN when none differs by more than 2 std.
  double other_minimum_chi2_difference = std::nan("");
};

// The Fisher information of one experiment at q and what goes with it: F = Gᵀ W G, the χ² of the
// residual, the number of data values, the part of χ² counted as model error (beyond the band of
// the stated noise, or all of it), and the noise levels used. Experiments with independent noise
// add: F = Σ_e F_e, χ² = Σ χ²_e, systematic = Σ systematic_e (docs/theory.md §6.5).
struct FisherInformation {
  MatrixXd F;
  double chi2 = 0;
  long data_values = 0;
  double systematic = 0;
  std::vector<double> noise_std;
  bool stated_noise = true;  // every level stated (scenario or truth.json), none from the residual
  FisherInformation& operator+=(const FisherInformation& o);
};
// `sensors` supplies each sensor's stated noise_std (<= 0: unknown).
FisherInformation fisher_information(Objective& objective, const std::vector<io::SensorSpec>& sensors, const VectorXd& q);
// The same from the model's outputs Y (samples × sensors) and their sensitivities G (row
// sample · sensors + sensor, one column per parameter) at the estimate.
FisherInformation fisher_information(const Measurements& data, const MatrixXd& Y, const MatrixXd& G,
                                     const std::vector<io::SensorSpec>& sensors);
// std, resolution, condition number and the flags from a Fisher information (one experiment's or
// a sum of several).
// `names` (optional): the parameters' names, with which an unseen direction between two parameters
// is described by the one combination the data fix (e.g. "EI/rho_A" of a free decay).
Identifiability identifiability_from(const FisherInformation& fi, const VectorXd& q,
                                     const std::vector<std::string>* names = nullptr);
// fisher_information then identifiability_from.
Identifiability analyse_identifiability(Objective& objective, const std::vector<io::SensorSpec>& sensors,
                                        const VectorXd& q);

}  // namespace scoleid::identify
