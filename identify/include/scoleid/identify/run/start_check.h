#pragma once
// What a measured record says of its own channels before any fit (docs/data.md §2.5): the
// record's sensors against the model's outputs at the starting point (an input's static offset is
// read off the data alone, problem.cpp input_offsets).
//
// At the start (the spectral start on a measured record, attempts.h) the model's modes sit where
// the record's peaks are, so over the first ten cycles of the record's lowest peak after the inputs
// begin to act (the window; the whole response when the record is shorter) each sensor's record m
// and the model's output y should agree in sign and roughly in size. Per sensor:
//   correlation  ρ = ⟨y, m⟩ / (‖y‖ ‖m‖),     scale  a = ⟨y, m⟩ / ⟨y, y⟩   (m ≈ a y)
// ρ < −0.5: the sensor reads the model's response inverted — a transducer mounted or wired the
// other way round, or, when every sensor does, an input of the other sign (named when one input
// is read from the data). |ρ| >= 0.5 and a outside [1/3, 3]: a size the handbook start cannot
// explain (a unit, a calibration; every sensor alike points at the input). Each finding is a
// warning that names the channel and the conditioning that states the fix; none refuses the run.
// An input read with a static offset (Problem::static_offsets) is set aside first: the model runs
// on the column less its mean, so a load cell's offset and its sign are both named in one run.
#include <complex>
#include <string>
#include <vector>

#include "scoleid/identify/inverse/objective.h"
#include "scoleid/identify/run/problem.h"

namespace scoleid::identify {

// The same start seen in frequency, per pair of the one input read from the data and a sensor:
// the record's and the model's frequency responses H1 = Z(f)/F(f) over the whole record (the
// discrete Fourier transforms of the sensor's record, of the model's output at the start and of the
// input's samples; no window: the transients of a tap or a chirp lie inside the record), at the
// bins where the input carries at least 10⁻³ of its largest amplitude, up to Nyquist or within the
// fitted band. At each of the record's spectral peaks: the two magnitudes, their ratio and the
// phase of the record's relative to the model's (deg, in (−180, 180]; near ±180 is a sign, a ratio
// far from 1 a scale or unit). run_report.cpp writes the curves as start_frf.csv / start_frf.png.
struct StartFrf {
  std::string input, sensor;
  std::vector<double> f;                          // Hz
  std::vector<std::complex<double>> measured, model;
  struct Line {
    double hz = 0.0, measured = 0.0, model = 0.0, ratio = 0.0, phase_deg = 0.0;
  };
  std::vector<Line> lines;
  // Over the bins where the input carries at least a tenth of its largest amplitude: the median of
  // |H_record|/|H_model| and of |phase(H_record/H_model)| (deg), a
  // scale and a sign less sensitive than a peak's, whose height also holds the start's damping
  // (a peak's height goes as 1/ζ).
  double median_ratio = 0.0, median_phase_deg = 0.0;
};

struct StartCheck {
  struct Sensor {
    std::string name;
    double correlation = 0.0, scale = 0.0;  // NaN where the model's or the record's window is zero
  };
  std::vector<Sensor> sensors;
  std::vector<StartFrf> frf;   // one per sensor, for a record with one input from the data
  std::string frf_note;        // why there is none ("" when there is)
  double from = 0.0, to = 0.0;        // the window [s]
  std::vector<std::string> warnings;  // one line each, naming the channel
};

// The check at q (one forward solve on the whole record). `objective` is left on the whole record.
StartCheck check_start(const Problem& problem, Objective& objective, const VectorXd& q);

}  // namespace scoleid::identify
