#pragma once
// Frequency response functions of a data file's columns, the record streamed (scole-data frf;
// docs/data.md §1.7): a force column and response columns of a time record of any length turned
// into FRF data (frf_data.h) in SI, without the record held in memory.
//
// Reading. A CSV is read in chunks of rows (data_files.h CsvReader) and each chunk handed to the
// Welch estimator (frf_estimate.h), so memory is the chunk and the estimator's O(N (S + 1)), not
// the record, and a CSV has no sample limit here. A Universal, LabVIEW Measurement or TDMS file
// is read whole (data_source.h; its sample limit holds), then handed over the same way. The
// harmonic-lines estimator fits all samples at once and reads the record whole (the limit holds).
//
// Time. The estimators need the sample rate only. Stated (sample_rate > 0): the first sample's
// time t0 and every time within half a step of t0 + k/rate. Otherwise the grid of the first
// 65 536 samples (time_grid.h: uniform within the column's written precision, the culprit named
// when not), and every later time within a quarter of a step of it; farther is a dropped sample,
// a second segment or another rate, refused with the sample and its time named.
//
// Units. The input column must hold a force, each response a displacement, velocity or
// acceleration (its response order 0, 1, 2), each with its unit from the file (a header's
// "[unit]", the column description beside a converted CSV, the UFF record, LVM/TDMS properties)
// or from `units`, which also replaces a unit the file states wrongly (a LabVIEW channel left at its
// default label), the note naming the replacement. The estimators are linear, so the values are read
// in their own units and each H turned into SI once: H_SI = H · c_response / c_force, its
// variance by the square (c the units' scale factors into m, m/s, m/s², N).
//
// Impact. The record is read whole (its sample limit holds) and taken as one segment under an
// exponential window: the FRFs are H at s = decay + iω (FrfData::decay), which a UFF dataset 58
// cannot state (write_uff_frf refuses them), with each value's variance from the responses' noise.
// The quiet start (quiet_start.h) ends where the force first departs from its median (its static
// offset) by a twentieth of its peak; each channel's mean there — its offset — is removed first:
// under e^{-at} an offset would dominate the lowest lines.
//
// Defaults. Segment: the largest power of two of samples not above the record's length / 4.5
// (eight Hann segments at 50 % overlap; the CSV's length counted from its line breaks before it is
// read), as scole-identify's frequency path takes it. Lines kept up to 0.8 of Nyquist (above it a
// DAQ's anti-alias filter shapes the record), or f_max.
// Every malformed or missing thing is an InputError of one line naming the file (and line or
// column) or option and the value.
#include <cstddef>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "scoleid/io/data_files.h"
#include "scoleid/io/frf_data.h"
#include "scoleid/io/frf_estimate.h"

namespace scoleid::io {

enum class RecordFrfEstimator { H1, H2, Lines, Impact };

struct RecordFrfOptions {
  std::string input;                          // the force column's name
  std::vector<std::string> responses;         // response columns (empty: every column but the input)
  std::map<std::string, std::string> units;   // column -> unit: where the file states none, or replacing its (noted)
  double sample_rate = 0;                     // Hz; 0: from the time column
  RecordFrfEstimator estimator = RecordFrfEstimator::H1;
  double segment = 0;                         // s; 0: the default above
  double overlap = 0.5;                       // Welch, in [0, 1)
  FrfWindow window = FrfWindow::Hann;
  double f_min = 0, f_max = 0;                // lines kept f_min < f <= f_max (0: 0.8 of Nyquist)
  std::vector<double> lines_hz;               // the lines estimator's frequencies
  // Impact (frf_estimate.h impact_frf): one hit from rest, the whole record one segment under
  // e^{-decay t} (decay < 0: ln 100 / T, a hundredth at the end); each response's noise level in
  // its column's own unit (column -> σ; the input's, if named, is σ_x), else its quiet start's
  // (quiet_start.h, before the force first exceeds a twentieth of its peak), else refused.
  double decay = -1.0;
  std::map<std::string, double> noise;
  // Called every 2^20 samples read, with the count so far (progress of a long file).
  std::function<void(std::size_t)> progress;
};

struct RecordFrf {
  FrfData data;                    // SI: per N; channels named by their columns
  std::vector<int> orders;         // per response: 0 displacement, 1 velocity, 2 acceleration
  double sample_rate = 0;          // Hz
  std::size_t samples = 0;         // read
  int segments = 0;                // Welch segments averaged (0 for lines)
  double effective_averages = 0;   // Welch K_eff (welch_effective_averages); periods for lines
  std::string note;                // what was estimated, one line
};

RecordFrf frf_of_record(const std::string& path, const CsvOptions& csv, const RecordFrfOptions& options);

}  // namespace scoleid::io
