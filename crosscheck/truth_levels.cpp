#include "scoleid/crosscheck/truth_levels.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <exception>
#include <mutex>
#include <thread>

#include "scoleid/io/error.h"
#include "scoleid/io/run_directory.h"

namespace scoleid::crosscheck {

std::vector<int> refinement(int first, int levels, int limit, const std::string& what) {
  std::vector<int> v;
  for (int l = 0; l < levels; ++l) {
    const long n = static_cast<long>(first) << l;
    if (n > limit)
      throw io::InputError(std::to_string(levels) + " levels from " + std::to_string(first) + " " + what + " reach " +
                           std::to_string(n) + ", above the limit " + std::to_string(limit));
    v.push_back(static_cast<int>(n));
  }
  return v;
}

std::vector<TruthLevel> run_truth_levels(const io::Scenario& scenario, const std::vector<int>& segments,
                                         const std::string& root, bool noise_free, bool progress) {
  io::Scenario base = scenario;
  if (noise_free)
    for (auto& s : base.sensors) s.noise_std = 0.0;
  const std::size_t L = segments.size();
  std::vector<TruthLevel> out(L);
  std::vector<std::exception_ptr> errors(L);
  // The levels are independent Simbody systems: they run concurrently, finest first (it costs
  // the most), one per hardware thread. Progress is per level, not per percent, when parallel.
  const unsigned threads = std::max(1u, std::min<unsigned>(std::thread::hardware_concurrency(), static_cast<unsigned>(L)));
  std::atomic<std::size_t> next{0};
  std::mutex print;
  auto worker = [&] {
    for (;;) {
      const std::size_t k = next.fetch_add(1);
      if (k >= L) return;
      const std::size_t l = L - 1 - k;
      const int n = segments[l];
      try {
        const auto t0 = std::chrono::steady_clock::now();
        io::Scenario sc = base;
        sc.truth.segments = n;
        model::TruthOptions opt;
        opt.segments = n;
        opt.progress = progress && threads == 1;
        if (progress) {
          std::lock_guard<std::mutex> lock(print);
          std::fprintf(stderr, "scole-crosscheck: Simbody truth, %d segments\n", n);
        }
        const std::string dir = root + "/n" + std::to_string(n);
        io::RunDirectory rd(dir, model::output_files(), "scole-crosscheck");
        const model::TruthResult res = model::run_truth(sc, opt);
        model::write_truth(res, rd);
        rd.commit();
        TruthLevel& t = out[l];
        t.segments = n;
        t.csv = dir + "/truth.csv";
        t.summary = res.summary;
        t.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      } catch (...) {
        errors[l] = std::current_exception();
        next = L;  // stop handing out levels
      }
    }
  };
  std::vector<std::thread> pool;
  for (unsigned i = 1; i < threads; ++i) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
  for (const auto& e : errors)
    if (e) std::rethrow_exception(e);
  return out;
}

}  // namespace scoleid::crosscheck
