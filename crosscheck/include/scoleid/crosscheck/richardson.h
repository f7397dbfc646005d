#pragma once
// Convergence under refinement (docs/theory.md §11).
//
// A quantity computed at resolutions n, r n, r² n (refinement ratio r > 1) that converges as
//     f(n) = f∞ + C n^(−p) + o(n^(−p))
// has the observed order
//     p_obs = log(|f(n) − f(r n)| / |f(r n) − f(r² n)|) / log r
// and the Richardson extrapolation from the two finest levels with an assumed order p
//     f∞ ≈ f(r² n) + (f(r² n) − f(r n)) / (r^p − 1),
// whose error is o(n^(−p)). p_obs is NaN when the differences are at round-off (both below
// `noise` in absolute value) or change sign (not yet asymptotic).
#include <vector>

namespace scoleid::crosscheck {

// Observed order from three levels f(n), f(rn), f(r²n).
double observed_order(double f_n, double f_rn, double f_r2n, double ratio, double noise = 0.0);
// Richardson extrapolation from f(coarse) and f(fine = ratio · coarse) with order p.
double richardson(double f_coarse, double f_fine, double ratio, double p);

}  // namespace scoleid::crosscheck
