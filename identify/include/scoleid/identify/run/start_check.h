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
#include <string>
#include <vector>

#include "scoleid/identify/inverse/objective.h"
#include "scoleid/identify/run/problem.h"

namespace scoleid::identify {

struct StartCheck {
  struct Sensor {
    std::string name;
    double correlation = 0.0, scale = 0.0;  // NaN where the model's or the record's window is zero
  };
  std::vector<Sensor> sensors;
  double from = 0.0, to = 0.0;        // the window [s]
  std::vector<std::string> warnings;  // one line each, naming the channel
};

// The check at q (one forward solve on the whole record). `objective` is left on the whole record.
StartCheck check_start(const Problem& problem, Objective& objective, const VectorXd& q);

}  // namespace scoleid::identify
