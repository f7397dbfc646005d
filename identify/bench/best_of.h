#pragma once
// The benchmarks' timing rule: the minimum wall-clock time over repetitions (steady_clock), the
// figure least disturbed by other load on the machine.
#include <algorithm>
#include <chrono>
#include <functional>

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

}  // namespace scoleid::identify::bench
