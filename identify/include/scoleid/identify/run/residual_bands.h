#pragma once
// Where in frequency a fit's residual sits (docs/theory.md §7.6): a fit test says how large the
// residual is; this says what it is made of.
//
// The residual r_j(t_k) = y_j − m_j of each sensor on the record's uniform grid (N samples, step
// Δt) is split by its discrete Fourier transform R_j(f_b), f_b = b/(NΔt), without a window or mean
// removal, so that by Parseval the bands' powers add up to the residual's mean square exactly:
//     Σ_k r_j(t_k)² / N  =  Σ_bands  P_j(band),   P_j(band) = Σ_{f_b in band} w_b |R_j(f_b)|² / N²
// (w_b = 2 for the one-sided bins between 0 and Nyquist, 1 at 0 and at Nyquist).
// The bands follow the identified model's modes f_1 < … < f_K (those below Nyquist): "at mode k"
// is [f_k − w_k, f_k + w_k], w_k = max(3/(NΔt), 5 ζ_k f_k) — three frequency bins, or the mode's
// half-power width five times over — and the gaps are "below mode 1", "between modes k and k+1"
// and "above mode K" up to Nyquist (two modes closer than their widths share the midpoint).
// Sensors of different units are compared relative to their own record: the share of a band is
//     s(band) = Σ_j P_j(band)/M_j  /  Σ_j Σ_bands P_j/M_j,    M_j = Σ_k m_j(t_k)² / N,
// and a residual sitting at the modes says the model's modes miss the record's (frequency,
// damping, shape), one between or above them says the record holds content no mode of the model
// carries there (folded images of modes above Nyquist in a record sampled without an anti-alias
// filter, an input misread between its samples, noise, another structure's vibration).
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "scoleid/identify/inverse/modal_uncertainty.h"

namespace scoleid::identify {

struct ResidualBands {
  struct Band {
    double from_hz = 0.0, to_hz = 0.0;
    std::string holds;         // "mode 2", "between modes 2 and 3", "below mode 1", "above mode 4", "whole record"
    int mode = 0;              // the mode the band is centred on (1-based), 0 for a gap
    std::vector<double> rms;   // per sensor: the residual's RMS in the band (sensor units)
    double share = 0.0;        // s(band), over all sensors relative to their records
  };
  std::vector<Band> bands;
  double at_modes = 0.0;       // Σ share of the bands at modes
  std::string summary;         // one line: the largest shares, and what a residual there means
  std::string note;            // why there is no split ("" when there is one)
};

// The split of (predicted − measured), both samples × sensors on the uniform grid t, by the modes.
// `explained`: the fit test passed (the summary then reads the split only; a residual within
// noise and allowance needs no reading of what it is made of).
ResidualBands residual_bands(const std::vector<double>& t, const Eigen::MatrixXd& measured, const Eigen::MatrixXd& predicted,
                             const std::vector<ModalEstimate>& modes, bool explained = false);

}  // namespace scoleid::identify
