#pragma once
// The band a fit compares model and data in (identification.band; docs/theory.md §6.8).
//
// A record from a real structure carries modes no Euler–Bernoulli model follows to the noise
// level; over a lightly damped record their phase drift is a systematic residual that the fit
// spreads over every parameter. A modal engineer fits a band. Here the band is a filter G applied
// to the inputs' samples and to the outputs' samples alike, before the fit:
//
//   z_G = G z,   f_G = G f,   and the model is driven by f_G.
//
// For a linear time-invariant model at rest before t0, driven by an input read from its samples
// through a fixed interpolation kernel on their uniform grid (here the 4-point cubic: a filtered
// input is smooth, and the cubic follows it to O((ω dt)⁴) where the linear interpolant's sinc²
// loses 0.6 % at a tenth of the sampling rate), the map from input samples to output samples is
// itself a discrete LTI system H_d. G is discrete LTI too, so H_d (G f) = G (H_d f): the model
// driven by the filtered input gives, at the sample times, exactly the filtered output of the model
// driven by the raw samples. Model and data
// are therefore compared through the same filter, and the cost, its gradient (the costate sees the
// filtered input and data and nothing else) and the Fisher matrix need no change. Filtering both
// sides causally keeps each side's phase distortion identical; it is not undone.
//
// G (io/band_filter.h): a causal Butterworth band-pass in second-order sections from rest — a low-pass of order 8 at
// f_hi and, for f_lo > 0, a high-pass of order 4 at f_lo — by the bilinear transform with the
// edges pre-warped (|G| = 1/√2 at f_lo and f_hi, up to the other edge's influence, (f_lo/f_hi)^8).
//
// White noise of variance σ² leaves the filter as coloured noise of variance g σ² per sample, g =
// Σ h_i² (the impulse response's energy, about the band's share of the Nyquist range): its samples
// are no longer independent — about g N of them are. The identifier states the noise level of the
// filtered data as σ √g and counts g N independent values where a χ² band is drawn; the Fisher
// matrix, formed with the filtered sensitivities, is scaled by g (equivalently: formed with σ), the
// information of the band alone, and so are the systematic share of χ² and the χ² differences of
// the mirror and other-minimum tests.
#include "scoleid/io/band_filter.h"

namespace scoleid::identify {

// The filter G itself (one implementation, shared with the truth's acquisition filter).
using BandFilter = io::BandFilter;

}  // namespace scoleid::identify
