#pragma once
// The sample times of a record as a DAQ's clock made them: uniform, t_k = t0 + k·step, and written
// to a file with finite precision (docs/data.md §1.5). A time column printed to 6 significant digits
// ("0.00146484" for 0.00146484375) has intervals that differ by a few parts in 10⁶; that jitter is
// the column's own rounding, not the clock's. uniform_grid finds the grid the times round to:
//   - the written precision: the fewest significant digits, and the fewest decimals, that reproduce
//     the times (a sample of up to 4096 of them);
//   - the grid by least squares over k (t0, step);
//   - uniform when every sample lies within its own rounding (half a unit of its last written
//     digit, by either reading, 5 % more) of the grid, plus three of the fitted grid's standard
//     errors there and 1e-9 of a step, and none a quarter of a step or more off it (writing that
//     coarse leaves no clock to recognise); else the sample farthest from
//     the grid, in steps, names the culprit (a dropped sample, a second segment, another rate).
// A stated sample rate (data.sample_rate) fixes the step: the times must lie within half a step of
// t0 + k/rate, and are replaced by the grid.
#include <optional>
#include <string>
#include <vector>

namespace scoleid::io {

struct TimeGrid {
  bool uniform = false;   // the times lie on t0 + k·step within their written precision
  double t0 = 0.0, step = 0.0;
  double max_shift = 0.0;  // largest |t_k − (t0 + k·step)| [s]
  std::size_t worst = 0;   // the sample farthest from the grid (index)
  std::string precision;   // how the times were written: "6 significant digits", "4 decimals", "full"

  // The grid's times, t0 + k·step, for n samples.
  std::vector<double> times(std::size_t n) const;
};

// The grid of the times t (at least 2, strictly increasing).
TimeGrid uniform_grid(const std::vector<double>& t);

// A stated rate [Hz]: the grid t[0] + k/rate; std::nullopt with `why` (the sample, how far off) when
// a sample lies half a step or more off it. Times that the file itself made as t0 + k·step from a
// step written to few digits (stated_step > 0, rounding: half a unit of its last digit; an LVM's
// Delta_X 0.000977 for 1/1024 s) are replaced by the stated rate's grid when 1/rate lies within that
// rounding of the step: the rate is what the written step rounds; otherwise as above.
std::optional<TimeGrid> stated_grid(const std::vector<double>& t, double rate, std::string* why, double stated_step = 0,
                                     double rounding = 0);

}  // namespace scoleid::io
