#pragma once
// The benchmarks' timing rule: the minimum wall-clock time over repetitions (steady_clock), the
// figure least disturbed by other load on the machine.
#include <algorithm>
#include <chrono>
#include <functional>
#include <utility>

namespace scoleid::identify::bench {

inline double best_of(int reps, const std::function<void()>& f) {
  double best = 1e300;
  for (int r = 0; r < reps; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  return best;
}

// Two runs compared by their ratio: timed alternately (f, g, f, g, ...), each its minimum, so that a
// slow spell of the machine falls on both alike.
inline std::pair<double, double> best_of_alternating(int reps, const std::function<void()>& f,
                                                     const std::function<void()>& g) {
  double bf = 1e300, bg = 1e300;
  for (int r = 0; r < reps; ++r) {
    bf = std::min(bf, best_of(1, f));
    bg = std::min(bg, best_of(1, g));
  }
  return {bf, bg};
}

}  // namespace scoleid::identify::bench
