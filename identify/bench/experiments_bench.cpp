// scole-experiments-bench: several experiments identified together on the machine's cores
// (identify/inverse/joint_misfit.h), measured side by side in one run.
//
// Four SCOLE runs — the reflector pulse and the shuttle moment of identify/examples/two-runs, each
// twice with its own noise draw — fitted jointly (EI, rho_A, GJ, rho_I_psi, Gauss–Newton) on 1
// thread and on T threads (default 2). Reported: the wall time of the identification (data
// synthesis excluded) per thread count — the smallest of --repeat alternating repetitions — their
// ratio, the solves, and whether the iteration tables are bit-identical. Exit 1 if they are not.
//   scole-experiments-bench [--threads T] [--repeat R] [--source DIR]   (DIR: the repository)
#include <chrono>
#include <cstdio>
#include <algorithm>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "scoleid/identify/inverse/joint_misfit.h"
#include "scoleid/identify/inverse/optimizers.h"
#include "scoleid/identify/run/problem.h"
#include "scoleid/io/error.h"

using namespace scoleid::identify;
using Clock = std::chrono::steady_clock;

#ifndef SCOLEID_SOURCE_DIR
#define SCOLEID_SOURCE_DIR "."
#endif

int main(int argc, char** argv) {
  int threads = 2, repeat = 2;
  std::string source = SCOLEID_SOURCE_DIR;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--threads") && i + 1 < argc) threads = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--source") && i + 1 < argc) source = argv[++i];
    else if (!std::strcmp(argv[i], "--repeat") && i + 1 < argc) repeat = std::max(1, std::atoi(argv[++i]));
    else {
      std::fprintf(stderr, "usage: scole-experiments-bench [--threads T] [--repeat R] [--source DIR]\n");
      return 2;
    }
  }
  try {
    const std::string dir = source + "/identify/examples/two-runs/";
    std::vector<std::unique_ptr<Problem>> problems;
    std::vector<std::string> names;
    for (unsigned draw : {0u, 1u})
      for (const char* s : {"reflector-pulse", "shuttle-moment"}) {
        auto sc = scoleid::io::load_scenario(dir + s + ".yaml");
        sc.simulation.seed += 10 * draw;
        problems.push_back(make_problem(sc, std::nullopt));
        names.push_back(std::string(s) + "-" + std::to_string(draw));
        auto& p = *problems.back();
        const double W = p.data.white_noise_integral(p.data.t.front(), p.data.t.back());
        for (double sd : p.noise_std) p.objective_options.weights.push_back(static_cast<double>(p.data.t.size()) / (sd * sd * W));
      }
    std::printf("%zu runs (%s", problems.size(), names[0].c_str());
    for (std::size_t i = 1; i < names.size(); ++i) std::printf(", %s", names[i].c_str());
    std::printf("), %d parameters, Gauss-Newton\n\n", problems[0]->params->size());
    std::printf("%8s %10s %6s %10s %10s %12s\n", "threads", "wall [s]", "iter", "forward", "sensitiv.", "cost");
    std::vector<OptimizerSummary> out(2);
    std::vector<double> wall(2, 1e300);
    for (int rep = 0; rep < repeat; ++rep)
    for (int which : {0, 1}) {
      const int t = which == 0 ? 1 : threads;
      std::vector<std::unique_ptr<Objective>> objs;
      std::vector<JointMisfit::Component> parts;
      for (std::size_t i = 0; i < problems.size(); ++i) {
        auto& p = *problems[i];
        objs.push_back(std::make_unique<Objective>(p.model(), *p.params, p.signals, p.data, p.objective_options));
        parts.push_back({names[i], objs.back().get()});
      }
      JointMisfit joint(parts, JointMisfitOptions{t});
      OptimizerOptions oo;
      oo.method = scoleid::io::Method::GaussNewton;
      const auto t0 = Clock::now();
      const OptimizerSummary sum = minimize(joint, problems[0]->params->initial(), oo);
      const double w = std::chrono::duration<double>(Clock::now() - t0).count();
      if (rep > 0 && !(sum.q == out[static_cast<std::size_t>(which)].q)) {
        std::fprintf(stderr, "scole-experiments-bench: repetition %d differs from the first\n", rep);
        return 1;
      }
      out[static_cast<std::size_t>(which)] = sum;
      wall[static_cast<std::size_t>(which)] = std::min(wall[static_cast<std::size_t>(which)], w);
      long fwd = 0, sens = 0;
      for (const auto& o : objs) {
        fwd += o->counters().forward_solves;
        sens += o->counters().sensitivity_solves;
      }
      std::printf("%8d %10.3f %6d %10ld %10ld %12.6e\n", joint.threads(), w, sum.iterations_done, fwd, sens, sum.cost);
    }
    bool same = out[0].iterations.size() == out[1].iterations.size();
    for (std::size_t k = 0; same && k < out[0].iterations.size(); ++k)
      same = out[0].iterations[k].cost == out[1].iterations[k].cost && out[0].iterations[k].q == out[1].iterations[k].q;
    std::printf("\nbest of %d: wall(%d threads) / wall(1 thread) = %.3f / %.3f s = %.3f; iteration tables %s\n", repeat, threads,
                wall[1], wall[0], wall[1] / wall[0],
                same ? "bit-identical" : "DIFFER");
    std::printf("estimate:");
    for (Eigen::Index i = 0; i < out[0].q.size(); ++i) std::printf(" %s = %.7g", problems[0]->params->names()[static_cast<std::size_t>(i)].c_str(), out[0].q[i]);
    std::printf("\n");
    return same ? 0 : 1;
  } catch (const scoleid::io::InputError& e) {
    std::fprintf(stderr, "scole-experiments-bench: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "scole-experiments-bench: failed: %s\n", e.what());
    return 1;
  }
}
