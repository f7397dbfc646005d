// scole-sections-bench: how the identifier scales with the number of EI sections, how robust
// Gauss–Newton is from nearby starts, and what checkpointing costs. Parts printed as tables
// (and written to --json PATH):
//   1. EI(x) on N sections (N = 2, 8, 32, 64 by default), Gauss–Newton and L-BFGS: a simply
//      supported beam, 64 identifier elements, synthetic data on 128 elements, two loads, 16
//      displacement sensors, 10 s at 0.01 s, the identifier's automatic time step (from what the
//      data contain, the same for every N). Each (N, method) runs in its own child process (this program
//      re-executed with the hidden --case mode) so that its peak RSS is its own, with a timeout.
//      Reported: iterations, termination, wall time, step, solve counts, errors against the
//      truth, peak RSS; then wall(N=64)/wall(N=2) and the iteration counts side by side.
//   2. Four EI sections + rho_A from the closed-form modal series (paper-beam-1 geometry, one
//      midspan sensor, 20 elements), Gauss–Newton from ten starts ±15 % / ±30 % around the truth,
//      with the fit test and its restarts: whether a run reported as converged reached the truth in
//      every parameter not flagged (false convergence). The antisymmetric combination of the
//      sections is invisible to the one midspan sensor under the midspan load: the Fisher test
//      flags it, and an error there is not a false claim.
//   3. Checkpointing (docs/theory.md §7.9): part 1's problem, a fixed workload of gradients and
//      Gauss–Newton products at several checkpoint spacings, peak RSS against wall time.
//   4. (--part 4) part 1's problem over 5 s against the exact-discretisation least-squares peer
//      (peers/exact_discretisation.py): the same data and model, wall time and RMS error of each.
// Wall times are single runs (steady_clock), not minima over repetitions.
#include <sys/resource.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <poll.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "scoleid/identify/fe/analytic_beam.h"
#include "scoleid/identify/run/identify_run.h"

using namespace scoleid::identify;
using Clock = std::chrono::steady_clock;
using nlohmann::json;

namespace {

constexpr double kLength = 10.0;
constexpr double kRhoA = 67.0;
constexpr double kEI0 = 23000.0;

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// Part 1 options passed on to the child processes: each sensor's noise std (m; 0 = noise-free
// data) and the smoothness prior (identification.smoothness: < 0 = the discrepancy principle).
double g_noise = 0.0;
double g_smoothness = 0.0;
// Checkpoint spacing of the objective (ObjectiveOptions::checkpoint_points): −1 = the default
// (checkpoint beyond the trajectory budget), 0 = always store the whole state, L > 0 = every L points.
long g_checkpoint = -1;
// Seed of part 1's noise (the scenario's simulation.seed); < 0 = the scenario's own.
long g_seed = -1;
// Part 1's identifier step (identification.time_step, s); 0 = the automatic rule (§5.2).
double g_time_step = 0.0;
// Part 1's automatic step rule (identification.step_rule): parameters | data.
std::string g_step_rule = "parameters";

void apply_checkpoint(ObjectiveOptions& o, long L) {
  if (L < 0) return;
  o.checkpoint_points = L;
  if (L == 0) o.trajectory_bytes = std::numeric_limits<double>::infinity();
}

// The true stiffness profile of part 1, EI(x) = 23000 (1 + 0.3 sin(πx/L) + 0.1 cos(3πx/L)).
double ei_profile(double x) { return kEI0 * (1.0 + 0.3 * std::sin(M_PI * x / kLength) + 0.1 * std::cos(3.0 * M_PI * x / kLength)); }

// ---------------------------------------------------------------------------------------------
// Part 1: EI(x) on N sections

// beam-ei8 (its step load at 3.1 m and haversine at 6.7 m) with the truth on N sections (the
// profile at each section's centre, so it is representable exactly), 16 sensors at the centres of
// 16 equal intervals, 64 identifier elements, data on 128, automatic time step.
scoleid::io::Scenario part1_scenario(int N) {
  auto sc = scoleid::io::load_scenario("beam-ei8");
  sc.name = "sections-" + std::to_string(N);
  sc.beam.length = kLength;
  sc.beam.rho_A = kRhoA;
  sc.beam.EI.assign(static_cast<std::size_t>(N), 0.0);
  for (int k = 0; k < N; ++k) sc.beam.EI[static_cast<std::size_t>(k)] = ei_profile((k + 0.5) * kLength / N);
  const auto sensor_template = sc.sensors.front();
  sc.sensors.clear();
  for (int i = 0; i < 16; ++i) {
    auto s = sensor_template;
    s.name = "w" + std::to_string(i + 1);
    s.location = (i + 0.5) * kLength / 16.0;
    sc.sensors.push_back(s);
  }
  sc.simulation.duration = 10.0;
  sc.simulation.sample_interval = 0.01;
  sc.identification.parameterization = "physical";
  sc.identification.sections = 0;  // the beam's own N sections
  sc.identification.estimate.clear();
  for (int k = 1; k <= N; ++k) sc.identification.estimate.push_back("EI_" + std::to_string(k));
  sc.identification.initial.clear();
  sc.identification.initial["EI"] = 30000.0;
  sc.identification.elements = 64;
  sc.identification.data_elements = 128;
  sc.identification.time_step = g_time_step;  // 0: automatic, what is being measured
  sc.identification.step_rule = *scoleid::io::parse<scoleid::io::StepRule>(g_step_rule);
  for (auto& sensor : sc.sensors) sensor.noise_std = g_noise;
  if (g_seed >= 0) sc.simulation.seed = static_cast<unsigned>(g_seed);
  sc.identification.smoothness = g_smoothness;
  return sc;
}

// RMS and max relative error of the estimate over the parameters with a known true value.
std::pair<double, double> rel_errors(const Problem& p, const VectorXd& q) {
  double sum = 0.0, worst = 0.0;
  int n = 0;
  for (int i = 0; i < q.size(); ++i) {
    const auto it = p.true_values.find(p.params->names()[static_cast<std::size_t>(i)]);
    if (it == p.true_values.end()) continue;
    const double e = std::abs(q[i] / it->second - 1.0);
    sum += e * e;
    worst = std::max(worst, e);
    ++n;
  }
  return {n ? std::sqrt(sum / n) : NAN, n ? worst : NAN};
}

// A child's result: one JSON line on stdout (the parent reads the last); exit 1 on an error.
int emit(const json& out) {
  std::fflush(stdout);
  std::printf("%s\n", out.dump().c_str());
  std::fflush(stdout);
  return out.contains("error") ? 1 : 0;
}

// The hidden --case mode: one identification, one JSON line on stdout.
int run_case(int N, const std::string& method, bool compute_std) {
  json out{{"N", N}, {"method", method}};
  try {
    const auto t0 = Clock::now();
    auto p = make_problem(part1_scenario(N), std::nullopt);
    apply_checkpoint(p->objective_options, g_checkpoint);
    out["setup_seconds"] = seconds_since(t0);
    RunOptions ro;
    ro.method = scoleid::io::parse<scoleid::io::Method>(method).value();
    ro.compute_std = compute_std;
    ro.verbose = false;
    const auto t1 = Clock::now();
    const RunResult r = run_identification(*p, ro);
    out["wall_seconds"] = seconds_since(t1);
    const auto [rms, mx] = rel_errors(*p, r.estimate);
    out["method_used"] = scoleid::io::to_string(r.method);
    // Iterations of the whole run: every attempt's, with its coarse-to-fine levels; with the
    // discrepancy principle, of every weight tried (the first attempt counts the chosen weight's).
    int iterations = 0;
    for (const auto& a : r.attempts) iterations += a.iterations;
    if (!r.smoothness_path.empty()) {
      for (const auto& st : r.smoothness_path) iterations += st.iterations;
      iterations -= r.smoothness_path.back().iterations;
    }
    out["iterations"] = iterations;
    out["smoothness_weight"] = r.smoothness_weight;
    out["smoothness_met"] = r.smoothness_met;
    out["smoothness_expected_misfit"] = r.smoothness_expected_misfit;
    json path = json::array();
    for (const auto& st : r.smoothness_path)
      path.push_back({{"weight", st.weight}, {"data_misfit", st.data_misfit}, {"prior_cost", st.prior_cost},
                      {"iterations", st.iterations}, {"converged", st.converged}});
    out["smoothness_path"] = path;
    out["termination"] = to_string(r.summary.termination);
    out["converged"] = r.converged();
    out["optimizer_converged"] = r.summary.converged();
    out["explains_data"] = r.fit.explains_data;
    out["attempts"] = static_cast<int>(r.attempts.size());
    out["fit_ratio"] = r.fit.ratio;
    json att = json::array();
    for (const auto& a : r.attempts)
      att.push_back({{"strategy", a.strategy}, {"termination", a.termination}, {"cost", a.cost}, {"iterations", a.iterations},
                     {"explains_data", a.explains_data}, {"fit_message", a.fit_message}});
    out["attempt_list"] = att;
    out["chosen_strategy"] = r.attempts.empty() ? "" : r.attempts[static_cast<std::size_t>(r.chosen_attempt)].strategy;
    out["cost"] = r.summary.cost;
    out["step"] = p->objective_options.solver.step;
    out["forward_solves"] = r.counters.forward_solves;
    out["costate_solves"] = r.counters.costate_solves;
    out["sensitivity_solves"] = r.counters.sensitivity_solves;
    out["checkpointed_passes"] = r.counters.checkpointed_passes;
    out["optimizer_seconds"] = r.summary.wall_seconds;
    out["identifiability_seconds"] = r.identifiability_seconds;
    out["rms_error"] = rms;
    out["max_error"] = mx;
    if (compute_std) {
      int ok = 0;
      for (bool b : r.ident.identifiable) ok += b ? 1 : 0;
      out["identifiable"] = ok;  // parameters identify.json would report identifiable
    }
    out["parameters"] = static_cast<int>(r.estimate.size());
  } catch (const std::exception& e) {
    out["error"] = e.what();
  }
  return emit(out);
}

// Runs this program with `args` in a child process: its last JSON line as the row, peak RSS from
// wait4, killed after timeout_s.
json run_child_args(const std::vector<std::string>& args, double timeout_s) {
  json row = json::object();
  int fd[2];
  if (pipe(fd) != 0) {
    row["status"] = "error";
    row["error"] = std::string("pipe: ") + std::strerror(errno);
    return row;
  }
  const auto t0 = Clock::now();
  const pid_t pid = fork();
  if (pid < 0) {
    row["status"] = "error";
    row["error"] = std::string("fork: ") + std::strerror(errno);
    close(fd[0]);
    close(fd[1]);
    return row;
  }
  if (pid == 0) {
    dup2(fd[1], STDOUT_FILENO);
    close(fd[0]);
    close(fd[1]);
    std::vector<const char*> argv = {"scole-sections-bench"};
    for (const auto& a : args) argv.push_back(a.c_str());
    argv.push_back(nullptr);
    execv("/proc/self/exe", const_cast<char* const*>(argv.data()));
    _exit(127);
  }
  close(fd[1]);
  // Read the child's stdout until EOF or the deadline.
  std::string text;
  bool timed_out = false;
  for (;;) {
    const double left = timeout_s - seconds_since(t0);
    if (left <= 0) {
      timed_out = true;
      break;
    }
    pollfd pfd{fd[0], POLLIN, 0};
    const int rc = poll(&pfd, 1, static_cast<int>(std::min(left, 1.0) * 1000) + 1);
    if (rc < 0 && errno == EINTR) continue;
    if (rc <= 0) continue;
    char buf[4096];
    const ssize_t got = read(fd[0], buf, sizeof buf);
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0) break;  // EOF: the child has closed stdout (it is exiting)
    text.append(buf, static_cast<std::size_t>(got));
  }
  close(fd[0]);
  if (timed_out) kill(pid, SIGKILL);
  int status = 0;
  rusage ru{};
  while (wait4(pid, &status, 0, &ru) < 0 && errno == EINTR) {
  }
  row["elapsed_seconds"] = seconds_since(t0);
  row["peak_rss_mb"] = ru.ru_maxrss / 1024.0;  // Linux: kilobytes
  if (timed_out) {
    row["status"] = "timeout";
    return row;
  }
  // The last line that is a JSON object is the case's result (anything else on stdout is ignored).
  std::istringstream lines(text);
  std::string line, last;
  while (std::getline(lines, line))
    if (!line.empty() && line.front() == '{') last = line;
  if (last.empty()) {
    row["status"] = "error";
    row["error"] = WIFSIGNALED(status) ? "killed by signal " + std::to_string(WTERMSIG(status))
                                       : "no result, exit code " + std::to_string(WEXITSTATUS(status));
    return row;
  }
  json res = json::parse(last, nullptr, false);
  if (res.is_discarded()) {
    row["status"] = "error";
    row["error"] = "unparsable result line";
    return row;
  }
  for (auto it = res.begin(); it != res.end(); ++it) row[it.key()] = it.value();
  row["status"] = res.contains("error") ? "error" : "ok";
  return row;
}

// `--case N --method M` in a child process.
json run_child(int N, const std::string& method, bool compute_std, double timeout_s) {
  // Values pass to the child exactly (std::to_string keeps six decimals: a step below 5e-7 would
  // reach it as 0, the automatic step).
  auto exact = [](double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    return std::string(buf);
  };
  std::vector<std::string> args{"--case", std::to_string(N), "--method", method, "--noise", exact(g_noise),
                                "--smoothness-weight", exact(g_smoothness),
                                "--checkpoint", std::to_string(g_checkpoint), "--seed", std::to_string(g_seed),
                                "--time-step", exact(g_time_step), "--step-rule", g_step_rule};
  if (!compute_std) args.push_back("--no-std");
  json row = run_child_args(args, timeout_s);
  row["N"] = N;
  row["method"] = method;
  return row;
}

double num(const json& j, const char* key) {
  return j.contains(key) && j[key].is_number() ? j[key].get<double>() : NAN;
}

json part1(const std::vector<int>& sections, const std::vector<std::string>& methods, bool compute_std,
           double timeout_s) {
  std::printf("Part 1. EI(x) on N sections: 64 elements, data on 128, 16 sensors, 10 s at 0.01 s, automatic step,\n"
              "        start EI = 30000, one child process per case (timeout %.0f s, std %s)\n\n",
              timeout_s, compute_std ? "on" : "off");
  if (g_noise > 0 || g_smoothness != 0)
    std::printf("        sensor noise std %.3g m (stated, seed %ld), smoothness prior %s\n\n", g_noise, g_seed,
                g_smoothness < 0 ? "by the discrepancy principle" : std::to_string(g_smoothness).c_str());
  std::printf("%4s %-24s %5s %-18s %9s %10s %8s %8s %8s %10s %10s %6s %9s  %s\n", "N", "method", "iter", "termination",
              "wall[s]", "step h", "forward", "costate", "sensit.", "RMS err", "max err", "ident", "RSS[MB]",
              "chosen attempt");
  json rows = json::array();
  for (int N : sections)
    for (const auto& m : methods) {
      json r = run_child(N, m, compute_std, timeout_s);
      const std::string label = m == "auto" && r.contains("method_used") ? "auto:" + r["method_used"].get<std::string>() : m;
      if (r["status"] == "ok") {
        const std::string ident = r.contains("identifiable")
                                      ? std::to_string(r["identifiable"].get<int>()) + "/" + std::to_string(N)
                                      : "-";
        std::printf("%4d %-24s %5d %-18s %9.2f %10.3e %8ld %8ld %8ld %10.3e %10.3e %6s %9.1f  %s\n", N, label.c_str(),
                    r["iterations"].get<int>(), r["termination"].get<std::string>().c_str(), num(r, "wall_seconds"),
                    num(r, "step"), r["forward_solves"].get<long>(), r["costate_solves"].get<long>(),
                    r["sensitivity_solves"].get<long>(), num(r, "rms_error"), num(r, "max_error"), ident.c_str(),
                    num(r, "peak_rss_mb"), r.value("chosen_strategy", std::string()).c_str());
      } else {
        std::printf("%4d %-24s %5s %-18s %9.2f %10s %8s %8s %8s %10s %10s %6s %9.1f  %s\n", N, label.c_str(), "-",
                    r["status"].get<std::string>().c_str(), num(r, "elapsed_seconds"), "-", "-", "-", "-", "-", "-",
                    "-", num(r, "peak_rss_mb"), r.value("error", std::string()).c_str());
      }
      std::fflush(stdout);
      rows.push_back(r);
    }
  const auto find = [&](int N, const std::string& m) -> const json* {
    for (const auto& r : rows)
      if (r["N"] == N && r["method"] == m) return &r;
    return nullptr;
  };
  // Scaling: wall(N=64)/wall(N=2), or largest over smallest N when those two were not both run.
  const int lo = sections.empty() ? 0 : *std::min_element(sections.begin(), sections.end());
  const int hi = sections.empty() ? 0 : *std::max_element(sections.begin(), sections.end());
  const bool standard = std::count(sections.begin(), sections.end(), 2) && std::count(sections.begin(), sections.end(), 64);
  const int a = standard ? 2 : lo, b = standard ? 64 : hi;
  json scaling = json::object();
  std::printf("\n   wall(N=%d) / wall(N=%d) and peak RSS at N=%d:\n", b, a, b);
  for (const auto& m : methods) {
    const json* ra = find(a, m);
    const json* rb = find(b, m);
    const bool ok = ra && rb && (*ra)["status"] == "ok" && (*rb)["status"] == "ok";
    const double ratio = ok ? num(*rb, "wall_seconds") / num(*ra, "wall_seconds") : NAN;
    const double rss = rb ? num(*rb, "peak_rss_mb") : NAN;
    std::printf("   %-24s ratio %8.2f%s   peak RSS %8.1f MB%s\n", m.c_str(), ratio, ok ? "" : " (n/a)", rss,
                rb && (*rb)["status"] != "ok" ? (" (" + (*rb)["status"].get<std::string>() + ")").c_str() : "");
    scaling[m] = {{"N_low", a}, {"N_high", b}, {"wall_ratio", ratio}, {"peak_rss_mb_high", rss}};
  }
  // Crossover: iterations of each optimiser at each N, side by side.
  std::printf("\n   iterations (crossover):\n   %4s", "N");
  for (const auto& m : methods) std::printf(" %14s", m.c_str());
  std::printf("\n");
  for (int N : sections) {
    std::printf("   %4d", N);
    for (const auto& m : methods) {
      const json* r = find(N, m);
      if (r && (*r)["status"] == "ok")
        std::printf(" %14d", (*r)["iterations"].get<int>());
      else
        std::printf(" %14s", r ? (*r)["status"].get<std::string>().c_str() : "-");
    }
    std::printf("\n");
  }
  std::printf("\n");
  return {{"cases", rows}, {"scaling", scaling}, {"timeout_seconds", timeout_s}, {"compute_std", compute_std}};
}

// ---------------------------------------------------------------------------------------------
// Part 3: the memory/recompute curve of checkpointing (docs/theory.md §7.9)

constexpr int kCurveEvaluations = 3;  // gradients and Gauss–Newton products each, per case

// The hidden --curve-case mode: part 1's problem on N sections, then kCurveEvaluations gradients
// and products at the start with checkpoint spacing L (−2 = set-up only, the floor of the RSS).
int run_curve_case(int N, long L) {
  json out{{"N", N}, {"L", L}};
  try {
    auto p = make_problem(part1_scenario(N), std::nullopt);
    apply_checkpoint(p->objective_options, L);
    Objective o(p->model(), *p->params, p->signals, p->data, p->objective_options);
    const VectorXd q = p->params->initial();
    const double h = p->objective_options.solver.step;
    out["points"] = std::ceil((p->data.t.back() - p->data.t.front()) / h) + 1.0;
    out["dof"] = p->model().ndof;
    if (L != -2) {
      const auto t0 = Clock::now();
      VectorXd g, sum = VectorXd::Zero(q.size());
      for (int k = 0; k < kCurveEvaluations; ++k) {
        o.cost_and_gradient(q, g);
        VectorXd v = VectorXd::Zero(q.size());
        v[k % q.size()] = q[k % q.size()];
        sum += o.gauss_newton_product(q, v);
      }
      out["wall_seconds"] = seconds_since(t0);
      out["gradient_norm"] = g.norm();
      out["product_sum_norm"] = sum.norm();
      const auto& c = o.counters();
      out["forward_solves"] = c.forward_solves;
      out["costate_solves"] = c.costate_solves;
      out["checkpointed_passes"] = c.checkpointed_passes;
      out["checkpoint_resolves"] = c.checkpoint_resolves;
    }
  } catch (const std::exception& e) {
    out["error"] = e.what();
  }
  return emit(out);
}

json part3(int N, double timeout_s) {
  std::printf("Part 3. Checkpointing: memory against recomputation. Part 1's problem with N = %d, %d gradients and %d\n"
              "        Gauss-Newton products at the start, one child process per spacing L (points between\n"
              "        checkpoints); 'stored' keeps the whole state, 'default' is the trajectory-budget rule,\n"
              "        'set-up' only builds the problem (the RSS floor: data synthesis, model).\n\n",
              N, kCurveEvaluations, kCurveEvaluations);
  std::printf("%-9s %9s %9s %10s %9s %9s %12s %12s\n", "L", "wall[s]", "vs stored", "re-solves", "RSS[MB]",
              "above", "model[MB]", "|g| rel.dev");
  json rows = json::array();
  double stored_wall = NAN, stored_g = NAN, floor = NAN;
  for (long L : {-2L, 0L, -1L, 3000L, 1000L, 300L, 100L, 30L, 10L}) {
    json r = run_child_args({"--curve-case", std::to_string(N), "--checkpoint", std::to_string(L)}, timeout_s);
    r["L"] = L;
    const std::string label = L == -2 ? "set-up" : L == 0 ? "stored" : L == -1 ? "default" : std::to_string(L);
    const double rss = num(r, "peak_rss_mb");
    if (L == -2) floor = rss;
    if (r["status"] != "ok") {
      std::printf("%-9s %s %s\n", label.c_str(), r["status"].get<std::string>().c_str(), r.value("error", std::string()).c_str());
      rows.push_back(r);
      continue;
    }
    if (L == 0) {
      stored_wall = num(r, "wall_seconds");
      stored_g = num(r, "gradient_norm");
    }
    // The trajectories' model: stored = state + costate (+ tangent in a product) whole; checkpointed
    // = points/L checkpoints + 2 state segments + 1 costate window, plus the outputs (16 sensors).
    const double pts = num(r, "points"), n = num(r, "dof"), row = n * 3.0 * 8.0 / 1048576.0;
    double model = NAN;
    if (L == 0) model = 3.0 * pts * row;
    else if (L > 0) model = (pts / static_cast<double>(L) + 3.0 * static_cast<double>(L)) * row + pts * 16 * 3 * 8 / 1048576.0;
    const double w = num(r, "wall_seconds");
    std::printf("%-9s %9.2f %9.3f %10.0f %9.1f %9.1f %12.2f %12.1e\n", label.c_str(), w, w / stored_wall,
                num(r, "checkpoint_resolves"), rss, rss - floor, model,
                L == -2 ? NAN : std::abs(num(r, "gradient_norm") / stored_g - 1.0));
    r["model_mb"] = model;
    rows.push_back(r);
    std::fflush(stdout);
  }
  std::printf("\n");
  return {{"N", N}, {"evaluations", kCurveEvaluations}, {"cases", rows}};
}

// ---------------------------------------------------------------------------------------------
// Part 2: 4 sections + rho_A from analytic data

scoleid::io::Scenario part2_scenario(const std::map<std::string, double>& initial) {
  auto sc = scoleid::io::load_scenario("paper-beam-1");
  sc.identification.parameterization = "physical";
  sc.identification.sections = 4;
  sc.identification.estimate = {"EI_1", "EI_2", "EI_3", "EI_4", "rho_A"};
  sc.identification.initial = initial;
  sc.identification.elements = 20;
  sc.identification.model_error = 0.0;  // the closed-form series solves the model's own equations
  return sc;
}

// The closed-form modal series (2000 terms) at the scenario's sample times: no FE in the data.
Measurements series_data(const scoleid::io::Scenario& sc) { return synthesize_series(sc, 2000); }

json part2() {
  std::printf("Part 2. EI_1..EI_4 + rho_A from the modal series (paper-beam-1: midspan step load and sensor, 20 elements),\n"
              "        Gauss-Newton; truth EI_i = 23000, rho_A = 67\n\n");
  struct Start {
    std::string label;
    std::map<std::string, double> initial;
  };
  std::vector<Start> starts;
  const auto pct = [](double f) {
    char b[16];
    std::snprintf(b, sizeof b, "%+.0f%%", 100.0 * (f - 1.0));
    return std::string(b);
  };
  for (double s : {0.15, 0.30}) {
    for (double fe : {1.0 + s, 1.0 - s})
      for (double fr : {1.0 + s, 1.0 - s})
        starts.push_back({"EI " + pct(fe) + " rhoA " + pct(fr), {{"EI", kEI0 * fe}, {"rho_A", kRhoA * fr}}});
    // Mixed: sections alternating +s/−s, rho_A at its true value.
    std::map<std::string, double> mixed{{"rho_A", kRhoA}};
    for (int k = 1; k <= 4; ++k) mixed["EI_" + std::to_string(k)] = kEI0 * (k % 2 ? 1.0 + s : 1.0 - s);
    starts.push_back({"EI " + pct(1.0 + s) + "/" + pct(1.0 - s) + " alt.", mixed});
  }
  Measurements data = series_data(scoleid::io::load_scenario("paper-beam-1"));

  std::printf("%-22s %5s %-18s %5s %11s %10s %10s %10s %10s %10s %10s %6s %3s %s\n", "start", "iter", "termination", "conv",
              "J", "EI_1", "EI_2", "EI_3", "EI_4", "rho_A", "max err", "<=1e-2", "att", "chosen attempt");
  json rows = json::array();
  int false_conv = 0;
  for (const auto& st : starts) {
    json row{{"start", st.label}, {"initial", st.initial}};
    try {
      auto p = make_problem(part2_scenario(st.initial), std::nullopt);
      p->data = data;
      p->data_source = "modal series";
      p->origin = Problem::DataOrigin::Caller;
      RunOptions ro;
      ro.method = scoleid::io::Method::GaussNewton;
      ro.compute_std = true;
      ro.verbose = false;
      const auto t0 = Clock::now();
      const RunResult r = run_identification(*p, ro);
      // Worst error among the parameters the Fisher test did not flag.
      double worst_claimed = 0.0;
      for (int i = 0; i < r.estimate.size(); ++i)
        if (r.ident.identifiable.size() > static_cast<std::size_t>(i) && r.ident.identifiable[static_cast<std::size_t>(i)])
          worst_claimed = std::max(worst_claimed, std::abs(r.estimate[i] / p->true_values.at(p->params->names()[static_cast<std::size_t>(i)]) - 1.0));
      const double wall = seconds_since(t0);
      json errs = json::object();
      std::vector<double> e;
      double worst = 0.0;
      for (int i = 0; i < r.estimate.size(); ++i) {
        const auto& name = p->params->names()[static_cast<std::size_t>(i)];
        const double ei = r.estimate[i] / p->true_values.at(name) - 1.0;
        e.push_back(ei);
        errs[name] = ei;
        worst = std::max(worst, std::abs(ei));
      }
      const bool ok = worst <= 1e-2;
      if (r.converged() && worst_claimed > 1e-2) ++false_conv;
      std::printf("%-22s %5d %-18s %5s %11.3e", st.label.c_str(), r.summary.iterations_done,
                  to_string(r.summary.termination), r.converged() ? "yes" : "no", r.summary.cost);
      for (double v : e) std::printf(" %+10.2e", v);
      std::printf(" %10.2e %6s %3zu %s\n", worst, ok ? "yes" : "NO", r.attempts.size(),
                  r.attempts[static_cast<std::size_t>(r.chosen_attempt)].strategy.c_str());
      row.update({{"iterations", r.summary.iterations_done},
                  {"termination", to_string(r.summary.termination)},
                  {"converged", r.converged()},
                  {"optimizer_converged", r.summary.converged()},
                  {"explains_data", r.fit.explains_data},
                  {"attempts", static_cast<int>(r.attempts.size())},
                  {"chosen_strategy", r.attempts[static_cast<std::size_t>(r.chosen_attempt)].strategy},
                  {"max_error_unflagged", worst_claimed},
                  {"cost", r.summary.cost},
                  {"step", p->objective_options.solver.step},
                  {"wall_seconds", wall},
                  {"relative_errors", errs},
                  {"max_error", worst},
                  {"within_1e-2", ok}});
    } catch (const std::exception& ex) {
      std::printf("%-22s error: %s\n", st.label.c_str(), ex.what());
      row["error"] = ex.what();
    }
    std::fflush(stdout);
    rows.push_back(row);
  }
  std::printf("\n   reported converged with an unflagged parameter off by > 1e-2 (false convergence): %d of %zu starts\n\n", false_conv,
              starts.size());
  return {{"starts", rows}, {"false_convergence", false_conv}};
}

// ---------------------------------------------------------------------------------------------

void write_json(const std::string& path, const json& j) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp);
    f << j.dump(2) << "\n";
    if (!f) throw std::runtime_error("cannot write " + tmp);
  }
  std::filesystem::rename(tmp, path);
}

// ---------------------------------------------------------------------------------------------
// Part 4: part 1's problem (5 s) against the exact-discretisation peer (bench/peers/): the same
// data, the same 64-element model, EI on N sections from the same start. scoleid runs in this
// process (identification only, no standard deviations: the peer computes none); the peer in
// python3 (numpy, scipy) on a JSON export of the problem (data, sampled loads, geometry), its own wall clock.

// The problem as the peer reads it.
json peer_problem(const scoleid::io::Scenario& sc, const Problem& p, int N) {
  json j;
  j["length"] = sc.beam.length;
  j["rho_A"] = sc.beam.rho_A;
  j["elements"] = sc.identification.elements;
  j["sections"] = N;
  json sensors = json::array(), loads_at = json::array(), loads = json::array(), data = json::array();
  for (const auto& s : sc.sensors) sensors.push_back(s.location);
  for (std::size_t i = 0; i < sc.inputs.size(); ++i) {
    loads_at.push_back(sc.inputs[i].location);
    json col = json::array();
    for (double t : p.data.t) col.push_back(p.signals[i](t));
    loads.push_back(col);
  }
  for (int k = 0; k < p.data.sensors(); ++k) {
    json col = json::array();
    for (Eigen::Index r = 0; r < p.data.z.rows(); ++r) col.push_back(p.data.z(r, k));
    data.push_back(col);
  }
  j["sensor_locations"] = sensors;
  j["load_locations"] = loads_at;
  j["t"] = p.data.t;
  j["loads"] = loads;
  j["data"] = data;
  j["initial_EI"] = std::vector<double>(static_cast<std::size_t>(N), sc.identification.initial.at("EI"));
  return j;
}

// The peer's result (its last JSON line), or {"error": …}.
// The interpreter: $SCOLEID_PYTHON, else the system's /usr/bin/python3 (where Debian's numpy and
// scipy are), else python3 on the PATH.
std::string peer_python() {
  if (const char* e = std::getenv("SCOLEID_PYTHON"); e && *e) return e;
  return std::filesystem::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
}

json run_peer(const std::string& problem_path) {
  const std::string cmd =
      "'" + peer_python() + "' '" + std::string(SCOLEID_PEER_SCRIPT) + "' '" + problem_path + "' 2>&1";
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) return {{"error", "cannot start python3"}};
  std::string last, line;
  char buf[4096];
  while (std::fgets(buf, sizeof buf, pipe)) {
    line += buf;
    if (!line.empty() && line.back() == '\n') {
      if (line.front() == '{')
        last = line;
      else
        std::fprintf(stderr, "peer: %s", line.c_str());
      line.clear();
    }
  }
  const int status = pclose(pipe);
  if (status != 0 || last.empty()) return {{"error", "the peer failed (exit status " + std::to_string(status) + ")"}};
  return json::parse(last);
}

double rms_against(const std::vector<double>& estimate, const std::vector<double>& truth) {
  double s = 0.0;
  for (std::size_t k = 0; k < truth.size(); ++k) s += std::pow(estimate[k] / truth[k] - 1.0, 2);
  return std::sqrt(s / static_cast<double>(truth.size()));
}

// Part 4's problem: part 1's over 5 s.
scoleid::io::Scenario part4_scenario(int N) {
  auto sc = part1_scenario(N);
  sc.simulation.duration = 5.0;
  return sc;
}

// scoleid on p (identification only, no standard deviations): wall seconds, RMS error of EI against
// the scenario's sections, whether converged.
struct Timed {
  double seconds, rms;
  bool converged;
  ObjectiveCounters counters;  // where the time went (every attempt and ladder level)
  int iterations;              // over all attempts
};
Timed identify_timed(Problem& p, const std::vector<double>& truth) {
  RunOptions ro;
  ro.compute_std = false;
  ro.verbose = false;
  const auto t0 = Clock::now();
  const RunResult r = run_identification(p, ro);
  const double seconds = seconds_since(t0);
  return {seconds, rms_against(std::vector<double>(r.estimate.data(), r.estimate.data() + r.estimate.size()), truth),
          r.converged(), r.counters, r.iterations_all_attempts()};
}

// The solves behind a scoleid row: printed under it and kept in the row's JSON.
json split_of(const Timed& t) {
  const ObjectiveCounters& c = t.counters;
  std::printf(
      "%6s   scoleid's solves: %d iterations; %ld forward %.2f s, %ld gradients (costate %.2f s), "
      "%ld sensitivity columns %.2f s, quadrature %.2f s\n",
      "", t.iterations, c.forward_solves, c.forward_seconds, c.gradient_evaluations, c.costate_seconds,
      c.sensitivity_solves, c.sensitivity_seconds, c.quadrature_seconds);
  return {{"iterations", t.iterations},
          {"forward_solves", c.forward_solves},
          {"forward_seconds", c.forward_seconds},
          {"gradient_evaluations", c.gradient_evaluations},
          {"costate_seconds", c.costate_seconds},
          {"sensitivity_solves", c.sensitivity_solves},
          {"sensitivity_seconds", c.sensitivity_seconds},
          {"quadrature_seconds", c.quadrature_seconds}};
}

json part4(const std::vector<int>& sections) {
  std::printf(
      "4. EI(x) against the exact-discretisation peer (64 elements, 16 sensors, 5 s at 0.01 s, start EI 30000)\n");
  std::printf("%6s %14s %10s %14s %10s %8s %8s\n", "N", "scoleid [s]", "rms err", "peer [s]", "rms err", "evals",
              "ratio");
  json rows = json::array();
  const auto dir = std::filesystem::temp_directory_path() / ("scole-sections-peer-" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  for (int N : sections) {
    const auto sc = part4_scenario(N);
    auto p = make_problem(sc, std::nullopt);
    const std::string path = (dir / ("problem-" + std::to_string(N) + ".json")).string();
    write_json(path, peer_problem(sc, *p, N));
    const Timed t = identify_timed(*p, sc.beam.EI);
    const double ours = t.seconds, ours_rms = t.rms;
    const json peer = run_peer(path);
    json row{{"N", N}, {"scoleid_seconds", ours}, {"scoleid_rms_error", ours_rms}, {"scoleid_converged", t.converged}};
    if (peer.contains("error")) {
      std::printf("%6d %14.3f %10.2e %14s\n", N, ours, ours_rms, peer["error"].get<std::string>().c_str());
      row["peer_error"] = peer["error"];
    } else {
      const double theirs = peer["wall_seconds"].get<double>();
      const double their_rms = rms_against(peer["estimate"].get<std::vector<double>>(), sc.beam.EI);
      std::printf("%6d %14.3f %10.2e %14.3f %10.2e %8d %8.1f\n", N, ours, ours_rms, theirs, their_rms,
                  peer["evaluations"].get<int>(), theirs / ours);
      row["peer_seconds"] = theirs;
      row["peer_rms_error"] = their_rms;
      row["peer_evaluations"] = peer["evaluations"];
      row["ratio"] = theirs / ours;
    }
    row["scoleid_split"] = split_of(t);
    rows.push_back(row);
  }
  // With the smoothness prior (the discrepancy principle) on the most sections: the principle needs
  // a stated noise level, so the data carry noise of 1 % of the largest response.
  if (!sections.empty()) {
    const int N = sections.back();
    auto sc = part4_scenario(N);
    const double peak = make_problem(sc, std::nullopt)->data.z.cwiseAbs().maxCoeff();
    for (auto& sensor : sc.sensors) sensor.noise_std = 0.01 * peak;
    sc.identification.smoothness = -1.0;
    auto p = make_problem(sc, std::nullopt);
    const Timed t = identify_timed(*p, sc.beam.EI);
    const double ours = t.seconds, rms = t.rms;
    std::printf("%6d %14.3f %10.2e   (scoleid, data with 1 %% noise, smoothness prior by the discrepancy principle)\n",
                N, ours, rms);
    rows.push_back({{"N", N},
                    {"prior", "discrepancy"},
                    {"scoleid_seconds", ours},
                    {"scoleid_rms_error", rms},
                    {"scoleid_split", split_of(t)}});
  }
  std::filesystem::remove_all(dir);
  std::printf("\n");
  return rows;
}

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

const char* kUsage =
    "usage: scole-sections-bench [--part 1|2|3|4] [--sections 2,8,32,64] [--methods gauss-newton,lbfgs]\n"
    "                            [--timeout S] [--no-std] [--json PATH] [--noise SD] [--smoothness S]\n"
    "                            [--checkpoint L] [--seed K] [--time-step H] [--step-rule parameters|data]\n"
    "  Part 1: EI(x) on N sections (64 elements, 16 sensors, automatic step unless --time-step), each (N, method) in "
    "a\n"
    "          child process: iterations, wall time, step, solves, errors, peak RSS; default sections\n"
    "          2,8,32,64, methods gauss-newton,lbfgs (auto also accepted), timeout 600 s per case.\n"
    "  Part 2: EI_1..EI_4 + rho_A from the analytic modal series, Gauss-Newton from 10 starts.\n"
    "  Part 3: checkpointing's memory/recompute curve: part 1's problem on the last --sections N (64),\n"
    "          3 gradients + 3 Gauss-Newton products per checkpoint spacing L, wall and peak RSS.\n"
    "  Part 4 (only when selected): part 1's problem over 5 s against the exact-discretisation peer\n"
    "          (identify/bench/peers/exact_discretisation.py; numpy and scipy, $SCOLEID_PYTHON or\n"
    "          /usr/bin/python3) on --sections (default\n"
    "          2,64): wall time and RMS error of each, the ratio; then scoleid with the smoothness prior.\n"
    "  Parts 1-3 run unless --part selects one. --no-std skips identifiability in part 1.\n"
    "  --checkpoint L sets part 1's checkpoint spacing: 0 = store the whole state, L > 0 = every L\n"
    "  points, -1 (default) = checkpoint when the state exceeds the trajectory budget (32 MiB).\n"
    "  --json PATH writes the results as JSON (temp file, then renamed).\n"
    "  --noise SD gives every sensor of part 1 a stated noise std SD [m] (noisy synthetic data);\n"
    "  --smoothness discrepancy|BETA sets part 1's smoothness prior (docs/theory.md §7.8).\n"
    "  --seed K seeds part 1's noise (default: the scenario's simulation.seed).\n"
    "  --time-step H fixes part 1's identifier step to H seconds at every N (default: the automatic\n"
    "  rule of docs/theory.md §5.2, which shortens the step as N grows).\n"
    "  --step-rule data gives part 1 the automatic step from the modes the data contain, the same\n"
    "  for every N (identification.step_rule; default parameters: modes up to min(N + 2, Nyquist)).\n";

}  // namespace

int main(int argc, char** argv) {
  int part = 0, case_n = -1, curve_n = -1;
  std::vector<int> sections = {2, 8, 32, 64};
  bool sections_given = false;
  using scoleid::io::Method;
  std::vector<std::string> methods = {scoleid::io::to_string(Method::GaussNewton), scoleid::io::to_string(Method::Lbfgs)};
  std::string method = scoleid::io::to_string(Method::GaussNewton), json_path;
  double timeout_s = 600.0;
  bool compute_std = true;
  try {
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      const auto value = [&]() -> std::string {
        if (i + 1 >= argc) throw std::invalid_argument(a + " needs a value");
        return argv[++i];
      };
      if (a == "--help" || a == "-h") {
        std::printf("%s", kUsage);
        return 0;
      } else if (a == "--part") {
        part = std::stoi(value());
        if (part < 1 || part > 4) throw std::invalid_argument("--part must be 1, 2, 3 or 4");
      } else if (a == "--sections") {
        sections_given = true;
        sections.clear();
        for (const auto& s : split(value())) {
          const int n = std::stoi(s);
          if (n < 1 || 64 % n != 0) throw std::invalid_argument("--sections: " + s + " does not divide 64 elements");
          sections.push_back(n);
        }
      } else if (a == "--methods") {
        methods = split(value());
        for (const auto& m : methods)
          if (const auto parsed = scoleid::io::parse<Method>(m); !parsed || *parsed == Method::SteepestDescent)
            throw std::invalid_argument("--methods: unknown method " + m);
      } else if (a == "--timeout") {
        timeout_s = std::stod(value());
      } else if (a == "--no-std") {
        compute_std = false;
      } else if (a == "--noise") {
        g_noise = std::stod(value());
        if (!(g_noise >= 0)) throw std::invalid_argument("--noise must be >= 0");
      } else if (a == "--smoothness") {
        const std::string v = value();
        g_smoothness = v == "discrepancy" ? -1.0 : std::stod(v);
        if (!(g_smoothness >= 0 || v == "discrepancy")) throw std::invalid_argument("--smoothness: discrepancy or >= 0");
      } else if (a == "--smoothness-weight") {  // hidden: as passed to a child (-1 = discrepancy)
        g_smoothness = std::stod(value());
      } else if (a == "--json") {
        json_path = value();
      } else if (a == "--case") {  // hidden: one part-1 case, JSON line on stdout
        case_n = std::stoi(value());
      } else if (a == "--checkpoint") {
        g_checkpoint = std::stol(value());
        if (g_checkpoint < -2) throw std::invalid_argument("--checkpoint must be >= 0 (or -1: the default; -2: set-up only)");
      } else if (a == "--seed") {
        g_seed = std::stol(value());
      } else if (a == "--step-rule") {
        g_step_rule = value();
        if (g_step_rule != "parameters" && g_step_rule != "data") throw std::invalid_argument("--step-rule: parameters or data");
      } else if (a == "--time-step") {
        g_time_step = std::stod(value());
        if (!(g_time_step >= 0)) throw std::invalid_argument("--time-step must be >= 0 (0: automatic)");
      } else if (a == "--curve-case") {  // hidden: one part-3 case, JSON line on stdout
        curve_n = std::stoi(value());
      } else if (a == "--method") {  // hidden, with --case
        method = value();
      } else {
        throw std::invalid_argument("unknown argument " + a);
      }
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "scole-sections-bench: %s\n%s", e.what(), kUsage);
    return 2;
  }
  if (case_n > 0) return run_case(case_n, method, compute_std);
  if (curve_n > 0) return run_curve_case(curve_n, g_checkpoint);

  std::printf("scole-sections-bench (wall clock, single runs)\n\n");
  json out = json::object();
  try {
    if (part == 0 || part == 1) out["part1"] = part1(sections, methods, compute_std, timeout_s);
    if (part == 0 || part == 2) out["part2"] = part2();
    if (part == 0 || part == 3) out["part3"] = part3(sections.empty() ? 64 : sections.back(), timeout_s);
    if (part == 4) out["part4"] = part4(sections_given ? sections : std::vector<int>{2, 64});
    if (!json_path.empty()) write_json(json_path, out);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "scole-sections-bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
