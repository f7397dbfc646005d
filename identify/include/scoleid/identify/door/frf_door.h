#pragma once
// The identifier's front door for frequency-domain data (identification.domain: frequency;
// docs/theory.md §6.10, §10.1b): the record or file resolved into the FRFs the run fits, every
// setting checked against it (the segment, the lines below Nyquist, a stated noise level for an
// impact's FRFs, a band that keeps lines, every line's value and variance finite).
//
// The data. Frequency response functions of the scenario's one input to every sensor:
//   - made from a time record (a data file, or the scenario's synthetic record) by
//       lines  the input's known lines (its sine and multisine terms, or identification.frf.lines):
//              a least-squares harmonic fit of every channel over the whole record, H = Y/X per
//              line, the variance from what the fit leaves in each channel (io/frf_estimate.h). For
//              steady sines and periodic multi-sines: no leakage, whatever the damping;
//       h1/h2  Welch's averaged segments (identification.frf.segment, overlap, window), the
//              variance from the segments' scatter (coherence); the lines up to 0.8 of Nyquist.
//     auto takes lines when the input's scenario signal is made of sines, else h1.
//   - or read from a UFF file of FRFs (function type 4, io/uff_frf.h) given as --data.
//   identification.band [f_lo, f_hi], when stated, keeps the lines within it. Every line's variance
//   is the data's own: the segments' scatter, the harmonic fit's remainder, a file's coherence or a
//   stated relative_std — never the model's residual. A variance estimated from ν degrees of
//   freedom is scaled by ν/(ν − 2), so that a value's expected weighted misfit is 1 (the F(2, ν)
//   law's mean), and the fit test's χ² band is widened by ν/(ν − 4) (its variance).
#include <vector>

#include "scoleid/identify/run/problem.h"
#include "scoleid/io/frf_data.h"

namespace scoleid::identify {

// The FRFs of a problem with identification.domain: frequency, made from its time record (p.data,
// p.signals) into p.frf, p.frf_sensors, p.frf_input, p.frf_variance_dof and p.frf_note.
// io::InputError naming the scenario field or the data.
void frf_from_record(Problem& p);
// The same from FRFs read from a file (`orders`: each channel's response derivative, 0 displacement,
// 1 velocity, 2 acceleration, converted to the scenario sensor's).
void frf_from_file(Problem& p, io::FrfData data, const std::vector<int>& orders);

}  // namespace scoleid::identify
