#pragma once
// Frequency response functions in a Universal File (datasets 58/58b, uff.h): reading the FRFs a
// shaker or hammer test exported into the product's FRF data (frf_data.h), and writing FRF data as
// an ASCII Universal File other tools read.
//
// Reading. The FRFs are the functions of type 4 (Frequency Response Function); type 6 (Coherence)
// holds their ordinary coherence γ². Options:
//   stations      scenario sensor ← "<node><sign><axis>" of its response, axis X Y Z RX RY RZ
//                 ("12+Y", "7-RZ"), or "<node>" for a scalar response (as uff_modes.h). The FRF
//                 of a station is the one whose response is that node and axis (the file's
//                 direction may have either sign) and whose reference is the excitation's.
//   reference     "<node><sign><axis>" of the excitation; "" = the one reference (node and axis)
//                 every FRF in the file shares.
//   relative_std  σ_k = relative_std·|H_k| for every value of an FRF without usable coherence.
//   averages      the averages behind the file's coherence: with both, the variance of a value is
//                 σ² = (1 − γ²)/(γ² · averages)·|H|². Each station needs coherence with averages,
//                 or relative_std.
// Signs. A direction names a signed axis: the file's response direction −Y means the response
// was measured along −Y. H is turned into the station's direction and into the reference's
// (when given): H = s_station · sgn(response direction) · s_reference · sgn(reference direction)
// · H_file. With reference "", the input's direction is that of the first FRF in the file.
// Lines. The abscissa must be frequency (specific data type 18) in Hz (units label Hz in any
// case, or none); the lines are the function's x values, strictly increasing. A line at exactly
// 0 Hz (the DC line analysers write first) is left out, with its coherence: frf_data.h's lines
// are > 0. Every station's FRF, and each coherence, must have the same lines.
// Units. The numerator (ordinate) must be a displacement (specific data type 8), velocity (11)
// or acceleration (12): the response order 0, 1 or 2 of the channel; the denominator must be an
// excitation force (13). Values are turned into SI from dataset 164 (SDRL: a value in file units
// divided by factor^exponent is SI; no dataset 164: SI) and the axes' length and force exponents:
//   H_SI = H_file · L^(a_den − a_num) · F^(b_den − b_num)
// (L, F the length and force factors; a, b the length and force exponents of the numerator and
// denominator). For the named systems (codes 2-8, 10) a factor written as the inverse of SDRL's
// (a foot as 3.048D-01) is read as SDRL's. When the factors do not cancel, the exponents must be
// those of a response per force (a_num − a_den = 1 for a translation, 0 for a rotation;
// b_num − b_den = −1), or the conversion would be silently wrong. Temperature exponents are not
// used.
// Every malformed or missing thing is an InputError of one line naming the file, the record
// (dataset 58 and line) or option field, and the value.
//
// Writing. write_uff_frf writes a header (151), the SI unit system (164), then per channel an
// ASCII dataset 58 of function type 4: complex double precision (ordinate type 6, 20 wide, 4
// values a line), abscissa frequency in Hz (specific type 18), ordinate displacement (8),
// velocity (11) or acceleration (12) by the channel's response order in m, m/s, m/s^2 (rad, rad/s,
// rad/s^2 at a rotation), denominator force (13) in N, response node and direction from the
// channel's station, reference from `reference` ("" = node 0, scalar), ID line 1 the sensor's
// name. A channel with coherence gets a dataset 58 of function type 6 beside it (real double
// precision, ID line 1 "<sensor> coherence"). Values are written to 13 significant digits
// (relative error below 5e-13), each with a blank before it. The abscissa is even (minimum and
// increment in the 13-wide header fields, to 7 significant digits) when that reproduces every line
// as closely as writing each one would (5e-7); else uneven, each line written before its values
// in 13 characters (7 significant digits). The variance is not
// written (the format has no place for it): a reader weights the values from the coherence and the
// averages, or by relative_std.
#include <string>
#include <utility>
#include <vector>

#include "scoleid/io/frf_data.h"
#include "scoleid/io/uff.h"

namespace scoleid::io {

struct UffFrfOptions {
  // scenario sensor name <- "<node><sign><axis>" of the response (as uff_modes.h)
  std::vector<std::pair<std::string, std::string>> stations;
  std::string reference;  // "<node><sign><axis>" of the excitation; "" = the one reference all FRFs share
  // How well the values are known, when the file has no coherence for a function (one of them must hold):
  double relative_std = 0;  // σ_k = relative_std·|H_k| for every value
  int averages = 0;         // with coherence functions in the file: σ² = (1−γ²)/(γ² · averages)·|H|²
  std::string source;       // where these options were given, for messages
};

// The FRFs of `file` (read from `path`, named in messages) at the stations, one channel per
// station in the options' order. estimator "file", averages options.averages, source `path`,
// input options.reference. `response_orders` (may be null) receives per channel the order of
// the response the file states: 0 displacement, 1 velocity, 2 acceleration; the caller converts
// it to the sensor's kind. InputError as described above.
FrfData frf_data_from_uff(const uff::File& file, const std::string& path, const UffFrfOptions& options,
                          std::vector<int>* response_orders = nullptr);

// Writes FRFs (function type 4, complex double, even abscissa in Hz, spec types by the response
// kind) and, where known, their coherence (function type 6) as dataset 58 ASCII, read by other
// tools (pyuff, SDynPy, MATLAB readers) as by read_file. `stations` gives each channel's sensor
// its "<node><sign><axis>"; `response_orders` per channel: 0 displacement, 1 velocity,
// 2 acceleration. Written to a temporary file and renamed into place. InputError naming the path
// for: a channel without a station or with a malformed one, two channels at one response, a
// response order outside 0..2, lines that are not strictly increasing and > 0, a channel whose
// values do not match the lines or are not finite, a coherence outside [0, 1].
void write_uff_frf(const std::string& path, const FrfData& data,
                   const std::vector<std::pair<std::string, std::string>>& stations, const std::string& reference,
                   const std::vector<int>& response_orders);

}  // namespace scoleid::io
