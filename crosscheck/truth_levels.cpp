#include "scoleid/crosscheck/truth_levels.h"

#include <chrono>
#include <cstdio>

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
  io::Scenario sc = scenario;
  if (noise_free)
    for (auto& s : sc.sensors) s.noise_std = 0.0;
  std::vector<TruthLevel> out;
  for (int n : segments) {
    const auto t0 = std::chrono::steady_clock::now();
    sc.truth.segments = n;
    model::TruthOptions opt;
    opt.segments = n;
    opt.progress = progress;
    if (progress) std::fprintf(stderr, "scole-crosscheck: Simbody truth, %d segments\n", n);
    const std::string dir = root + "/n" + std::to_string(n);
    io::RunDirectory rd(dir, model::output_files(), "scole-crosscheck");
    const model::TruthResult res = model::run_truth(sc, opt);
    model::write_truth(res, rd);
    rd.commit();
    TruthLevel l;
    l.segments = n;
    l.csv = dir + "/truth.csv";
    l.summary = res.summary;
    l.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    out.push_back(l);
  }
  return out;
}

}  // namespace scoleid::crosscheck
