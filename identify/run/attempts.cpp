#include "scoleid/identify/run/attempts.h"
#include "scoleid/identify/point_failure.h"

#include <stdexcept>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <optional>

#include "scoleid/identify/inverse/spectral_start.h"
#include "scoleid/identify/run/start_check.h"
#include "scoleid/identify/inverse/tied_parameterization.h"
#include "scoleid/identify/run/strategy.h"
#include "scoleid/io/error.h"
#include "scoleid/io/interrupt.h"
#include "scoleid/io/progress.h"

namespace scoleid::identify {

namespace {
bool same_point(const VectorXd& a, const VectorXd& b) { return a.size() == b.size() && (a.array() == b.array()).all(); }
}  // namespace

FitTest AttemptsContext::fit_at(const VectorXd& q, Alongside alongside, const std::function<void()>& also) {
  if (!same_point(fit_q, q)) {
    std::function<void()> meanwhile;
    if (alongside != Alongside::Nothing || also)
      meanwhile = [this, &q, alongside, &also] {
        if (alongside != Alongside::Nothing) attempt_cost(q);
        if (alongside == Alongside::CostAndRefits && alongside_fit) alongside_fit(q);
        if (also) also();
      };
    fit = test_fit(problem, objective, q, nullptr, meanwhile);
    fit_q = q;
  }
  return fit;
}

double AttemptsContext::attempt_cost(const VectorXd& q) {
  if (same_point(cost_q, q)) return cost;
  objective.set_horizon(objective.data_end());
  double J = INFINITY;
  try {
    if (q.allFinite()) J = objective.cost(q);
  } catch (const std::exception& e) {
    if (!point_failure(e)) throw;
  }
  cost_q = q;
  cost = std::isfinite(J) ? J : INFINITY;
  return cost;
}

FitTest AttemptsContext::fit_screen(const VectorXd& q, const std::function<void()>& if_not,
                                    const std::function<void()>& if_explained) {
  if (same_point(fit_q, q)) return fit;
  if (fit.discretisation.size() == 0) return fit_at(q, Alongside::Nothing, if_not);
  const FitTest screened = test_fit(problem, objective, q, &fit.discretisation);
  return screened.within_noise_and_discretisation ? fit_at(q, Alongside::Nothing, if_explained) : screened;
}

namespace {

// Paper-style iteration table: iteration, parameters, physical values, cost.
class Table {
public:
  // The physical columns of the paper form: rho_A, EI and what q3 stands for (the beam's
  // Kelvin–Voigt c_kv; zeta where there is no q3).
  Table(const Parameterization& p, bool physical_columns)
      : p_(p), phys_(physical_columns),
        columns_{"rho_A", "EI", physical_columns && p.physical(p.initial()).count("c_kv") ? "c_kv" : "zeta"} {}
  void header() const {
    io::progress("%5s", "iter");
    const int P = std::min(p_.size(), kMaxCols);
    for (int i = 0; i < P; ++i) io::progress(" %13s", p_.names()[static_cast<std::size_t>(i)].c_str());
    if (p_.size() > kMaxCols) io::progress(" %5s", "...");
    if (phys_)
      for (const char* n : columns_) io::progress(" %13s", n);
    io::progress(" %13s %8s\n", "cost", "horizon");
  }
  void row(const IterationRecord& r) const {
    io::progress("%5d", r.k);
    const int P = std::min(p_.size(), kMaxCols);
    for (int i = 0; i < P; ++i) io::progress(" %13.6g", r.q[i]);
    if (p_.size() > kMaxCols) io::progress(" %5s", "");
    if (phys_) {
      const auto ph = p_.physical(r.q);
      for (const char* n : columns_) {
        const auto it = ph.find(n);
        io::progress(" %13.6g", it == ph.end() ? std::nan("") : it->second);
      }
    }
    io::progress(" %13.6e %8.4g\n", r.cost, r.horizon);
    std::fflush(stdout);
  }

private:
  static constexpr int kMaxCols = 8;
  const Parameterization& p_;
  bool phys_;
  std::array<const char*, 3> columns_;
};

// One run's optimiser and its table.
struct Runner {
  AttemptsContext& c;
  Table table;
  void header() const {
    if (c.verbose) table.header();
  }
  OptimizerSummary minimize_from(const VectorXd& start, const OptimizerOptions& o) const {
    return minimize(c.objective, start, o, [this](const IterationRecord& rec) {
      if (rec.k == 0) c.iterates.clear();
      c.iterates.push_back(rec);
      io::check_interrupt();
      if (c.verbose) table.row(rec);
    });
  }
};

// The noise's expected misfit for the discrepancy principle: E J = Σ_k c_k W, c_k = ½ R_k σ_k²,
// W = E∫ñ² (Measurements::white_noise_integral), plus two standard deviations √(Σ_k c_k² V),
// V = Var ∫ñ² (the weights R_k differ by sensor, so a few sensors can carry most of J and the band
// is wider than that of N equal terms).
double noise_misfit(const Problem& p, const Objective& obj) {
  double expected = 0.0, variance = 0.0;
  const auto& R = obj.weights();
  // With a band the noise is smooth (the interpolant follows it: E∫ñ² = σ²(T − t0)) and only about g
  // of its samples are independent (Var ∫ñ² about 1/g times white noise's).
  const bool band = p.band_gain < 1.0;
  const double W = band ? obj.data_end() - obj.data_start() : p.data.white_noise_integral(obj.data_start(), obj.data_end());
  const double V = p.data.white_noise_integral_variance(obj.data_start(), obj.data_end()) / (band ? p.band_gain : 1.0);
  for (std::size_t k = 0; k < R.size(); ++k) {
    const double sd = k < p.noise_std.size() ? p.noise_std[k] : 0.0;
    if (!(sd > 0.0)) throw std::logic_error("discrepancy: sensor '" + p.data.names[k] + "' has no noise level (identify::check_run refuses it)");
    const double c = 0.5 * R[k] * sd * sd;
    expected += c * W;
    variance += c * c * V;
  }
  return expected + 2.0 * std::sqrt(variance);
}

// The fit test's floor beyond noise at q, ½ Σ_k R_k ((2 d_k)² + (m z_k)²)(T − t0) (fit_test.h: the
// discretisation estimate d_k and the declared model error m of the RMS signal z_k — a weight is
// chosen only if its fit would pass the fit test), plus what sampling leaves between the samples
// of a perfect fit (Objective::interpolation_misfit).
double fit_floor(AttemptsContext& c, const VectorXd& q) {
  Objective& obj = c.objective;
  const FitTest f = c.fit_at(q);
  const auto& R = obj.weights();
  const double span = obj.data_end() - obj.data_start();
  double floor = 0.0;
  for (std::size_t k = 0; k < R.size() && k < f.sensors.size(); ++k) {
    const double d = std::isfinite(f.sensors[k].discretisation) ? f.sensors[k].discretisation : 0.0;
    const double m = f.model_error * f.sensors[k].rms_signal;
    floor += 0.5 * R[k] * (4.0 * d * d + m * m) * span;
  }
  return floor + obj.interpolation_misfit(q);
}

// The smoothness weight by the discrepancy principle (docs/theory.md §7.8): β from 1 down by
// factors of 10, each solve from the previous estimate, until the data misfit is within the noise's
// expected misfit plus the fit test's floor — at the start when its fit already explains the data
// (`start_explained`: the ladder's last level, whose fit test is taken), else at the first weight's
// estimate. That β (the largest meeting it) and its estimate are kept; where none can (the misfit
// levels off above the target), the weight reached when it levels off. The stated noise levels are
// needed.
constexpr double kSmallestWeight = 1e-10;  // the path's last weight
OptimizerSummary discrepancy_path(const Runner& run, RunResult& r, const VectorXd& start, bool start_explained,
                                  OptimizerOptions oo) {
  const Problem& p = run.c.problem;
  double expected = r.smoothness_expected_misfit = noise_misfit(p, run.c.objective);
  VectorXd q = start;
  OptimizerSummary chosen;
  bool have = false, floor_added = false;
  auto add_floor = [&](const VectorXd& at) {
    if (floor_added || !at.allFinite()) return;
    floor_added = true;
    r.smoothness_expected_misfit = expected += fit_floor(run.c, at);
    if (run.c.verbose) io::progress("discrepancy: noise and the fit test's floor give a data misfit of %.4e\n", expected);
  };
  if (start_explained) add_floor(start);
  double previous_misfit = NAN, previous_drop = NAN;
  for (double beta = 1.0; beta >= kSmallestWeight; beta /= 10.0) {
    oo.smoothness_weight = beta;
    OptimizerSummary s = run.minimize_from(q, oo);
    const double misfit = s.cost - s.prior_cost;
    add_floor(s.q);
    r.smoothness_path.push_back({beta, misfit, s.prior_cost, s.iterations_done, s.converged()});
    if (run.c.verbose)
      io::progress("smoothness weight %.0e: data misfit %.4e (noise %.4e), prior %.4e, %s\n", beta, misfit, expected, s.prior_cost,
                  to_string(s.termination));
    if (s.q.allFinite()) q = s.q;
    // The next weight's run starts where this one ended, on the matrix it ended with.
    oo.start_matrix = s.q.allFinite() ? std::move(s.end_matrix) : MatrixXd();
    chosen = s;
    r.smoothness_weight = beta;
    have = true;
    if (!std::isfinite(misfit)) break;  // a run that failed (no cost): nothing to judge, not met
    if (misfit <= expected) {
      r.smoothness_met = true;
      break;
    }
    // The misfit levels off above the target where the fit already explains the data (the fit
    // test: within noise and discretisation): past the path's steepest decade (the drop per decade
    // shrinking), even this decade's drop at every decade left would not reach the target. A
    // smaller weight would loosen the prior for nothing; the principle is not met either way. (A
    // plateau between two drops of the path is not taken for this: there the data are not yet
    // explained.)
    const double drop = previous_misfit - misfit;
    if (std::isfinite(previous_drop) && drop < previous_drop &&
        misfit - drop * std::log10(beta / kSmallestWeight) > expected &&
        run.c.fit_at(q, AttemptsContext::Alongside::Cost).within_noise_and_discretisation) {  // (the attempt's cost, if it ends here)
      if (run.c.verbose)
        io::progress("the data misfit levels off above the noise's: the discrepancy cannot be met, weight %.0e kept\n",
                    beta);
      break;
    }
    previous_drop = drop;
    previous_misfit = misfit;
  }
  if (!have) throw std::logic_error("discrepancy_path: no weight tried");
  return chosen;
}

// The coarse-to-fine ladder (docs/theory.md §7.6): every sectional family tied into B = 1, 2, 4, …
// contiguous blocks, each level solved from the end of the previous one, until a level's fit is
// within noise and discretisation on the full model (finer levels would only refit what the data
// already hold) or B reaches the sections. Each level has its own automatic step (§5.2 for the
// level's P tied parameters: modes up to P + 2, never finer than the full run's; unless the scenario
// fixes the step or BDF chooses it): the coarse levels need only the low modes. Returns the start
// of the full parameterization's run.
struct Ladder {
  VectorXd q;
  int iterations = 0;
  std::string label;
  std::vector<RunResult::Attempt::Level> levels;
};
// The ladder's `first_point` where a run of the attempt's options follows from the level's estimate:
// that run's first evaluation (evaluate_start), kept by the objective.
std::function<void(const VectorXd&)> run_from_level(AttemptsContext& c) {
  return [&c](const VectorXd& q) { evaluate_start(c.objective, q, c.options); };
}

// One level of the ladder solved from `from` (the full parameterization's q): its summary, the
// expanded estimate, its step.
struct LevelSolve {
  int blocks = 0;
  OptimizerSummary summary;
  VectorXd q;
  double step = 0.0;
};
// `sweep_threads` as ObjectiveOptions' (1 beside another solve; the numbers do not depend on it).
LevelSolve solve_level(AttemptsContext& c, const std::vector<std::vector<int>>& families, int B, const VectorXd& from,
                       int sweep_threads = 0) {
  const Problem& p = c.problem;
  auto [group, gnames] = block_grouping(p.params->names(), families, B);
  TiedParameterization tied(*p.params, from, group, gnames);
  ObjectiveOptions lo = p.objective_options;
  if (sweep_threads > 0) lo.sweep_threads = sweep_threads;
  // (BDF chooses its own steps: the level keeps the full run's options.)
  if (!(p.scenario.identification.time_step > 0) && lo.solver.step > 0 &&
      lo.solver.integrator != SolverOptions::Integrator::Bdf)
    if (const IdentifierStep is = identifier_integration(p.scenario, p.model(), tied, p.signals); is.step > lo.solver.step) {
      lo.solver.step = is.step;
      lo.solver.dirk_table = is.dirk_table;
    }
  Objective level(p.model(), tied, p.signals, p.data, lo);
  OptimizerOptions ol = c.options;
  ol.method = resolve_method(io::Method::Auto, tied.size(), true, level.has_matrix_free_products());
  ol.smoothness_weight = 0.0;  // the tied levels are smooth by construction
  ol.smoothness_chains.clear();
  ol.continuation = p.scenario.identification.continuation_misfit > 0;
  LevelSolve out;
  out.blocks = B;
  out.step = lo.solver.step;
  out.summary = minimize(level, tied.initial(), ol, [&](const IterationRecord&) { io::check_interrupt(); });
  c.extra.Accumulate(level.counters());
  out.q = out.summary.q.allFinite() ? tied.expand(out.summary.q) : from;
  return out;
}

// The ladder's levels in turn. While a level's fit test solves the doubled mesh, this thread goes on
// with what likely follows (fit_screen): the next level after the first (whose test has no screen),
// the attempt's first point (`first_point`) after a level the screen passed; work that turns out
// not to follow is dropped (its solves stay in the counters).
Ladder coarse_to_fine(AttemptsContext& c, const std::vector<std::vector<int>>& families, const VectorXd& start,
                      const std::function<void(const VectorXd&)>& first_point) {
  std::size_t N = 0;
  for (const auto& f : families) N = std::max(N, f.size());
  Ladder out;
  out.q = start;
  out.label = "coarse-to-fine over";
  std::optional<LevelSolve> next;
  for (int B = 1; B < static_cast<int>(N); B *= 2) {
    LevelSolve level = next && next->blocks == B ? std::move(*next) : solve_level(c, families, B, out.q);
    next.reset();
    const OptimizerSummary& sl = level.summary;
    out.iterations += sl.iterations_done;
    out.q = level.q;
    out.label += " " + std::to_string(B);
    std::function<void()> if_not, if_explained;
    // (A speculative level that fails is solved again if it is needed: its error is the ladder's then.)
    if (2 * B < static_cast<int>(N))
      if_not = [&] {
        try {
          next = solve_level(c, families, 2 * B, out.q, 1);
        } catch (const std::exception& e) {
          if (!point_failure(e)) throw;
          next.reset();
        }
      };
    if (first_point) if_explained = [&] { first_point(out.q); };
    const bool explained = sl.q.allFinite() && c.fit_screen(out.q, if_not, if_explained).within_noise_and_discretisation;
    out.levels.push_back({B, level.step, sl.cost, sl.iterations_done, to_string(sl.termination), explained});
    if (c.verbose)
      io::progress("  %d block%s per family (step %.3g s): %s%s\n", B, B > 1 ? "s" : "", level.step,
                  sl.BriefReport().c_str(), explained ? "; the fit is within noise and discretisation" : "");
    if (explained) break;
  }
  out.label += " blocks, then " + std::to_string(N) + " sections";
  return out;
}

// An attempt's record: its cost over the whole record, whatever horizon the run ended on.
RunResult::Attempt attempt_record(AttemptsContext& c, const std::string& strategy, const OptimizerSummary& s,
                                  const FitTest& f, int iterations, std::vector<RunResult::Attempt::Level> levels) {
  RunResult::Attempt a;
  a.strategy = strategy;
  a.method = c.options.method;
  a.termination = to_string(s.termination);
  a.optimizer_converged = s.converged();
  c.objective.set_horizon(c.objective.data_end());
  // (taken on the whole record already by explained_by_level; otherwise usually alongside the fit test)
  a.cost = s.termination == OptimizerSummary::Termination::DataExplained ? s.cost : c.attempt_cost(s.q);
  if (!std::isfinite(a.cost)) a.cost = INFINITY;
  a.iterations = iterations;
  a.explains_data = f.explains_data;
  a.fit_message = f.message;
  a.estimate = s.q;
  a.levels = std::move(levels);
  return a;
}

std::size_t longest(const std::vector<std::vector<int>>& families) {
  std::size_t n = 0;
  for (const auto& f : families) n = std::max(n, f.size());
  return n;
}

// The ladder's last level explains the data within noise and discretisation (docs/theory.md §7.6):
// the full parameterization would start there and refit only what the data already hold, so it is
// not run; the attempt ends at the level's expanded estimate, its cost taken on the whole record.
OptimizerSummary explained_by_level(const Runner& run, const VectorXd& q, int blocks, std::size_t sections) {
  AttemptsContext& c = run.c;
  OptimizerSummary s;
  s.q = q;
  c.objective.set_horizon(c.objective.data_end());
  s.cost = c.objective.cost(q);
  s.termination = OptimizerSummary::Termination::DataExplained;
  s.message = "the " + std::to_string(blocks) + "-block level explains the data within noise and discretisation; " +
              std::to_string(sections) + " sections would refit only what the data already hold";
  IterationRecord rec;
  rec.cost = s.cost;
  rec.q = q;
  rec.gradient_norm = NAN;  // not evaluated: no step is taken from here
  rec.horizon = c.objective.data_end();
  s.iterations.push_back(rec);
  run.header();
  if (c.verbose) {
    run.table.row(rec);
    io::progress("%s\n", s.message.c_str());
  }
  return s;
}

// The spectral start (spectral_start.h) from q0; q empty when there is none or it is q0 within 1 %.
SpectralStart spectral_start_of(AttemptsContext& c, const VectorXd& q0) {
  const Problem& p = c.problem;
  SpectralStart ss;
  try {
    c.objective.set_horizon(c.objective.data_end());
    ss = spectral_start(p.model(), *p.params, q0, p.data, c.objective.predict(q0));
  } catch (const std::exception& e) {
    if (!point_failure(e)) throw;
    ss.q.resize(0);
    ss.note = e.what();
  }
  if (ss.q.size() == q0.size() && std::abs(std::log(ss.ratio)) < 0.01) {
    ss.q.resize(0);
    ss.note = "the model's peak is within 1 % of the record's";
  }
  return ss;
}

std::string spectral_label(const AttemptsContext& c, const SpectralStart& ss) {
  return "spectral start (x" + io::format_value(ss.ratio) + ", " + std::to_string(ss.pairs) + (ss.pairs == 1 ? " peak" : " peaks") +
         " lined up; " + io::format_value(ss.model_hz) + " Hz -> " + io::format_value(ss.data_hz) + " Hz), " + io::to_string(c.options.method);
}

// The first attempt: plain or from the ladder, with the prior's given or discrepancy weight. On a
// measured record without sections the plain attempt starts from the spectral start when it moves
// the frequencies by more than 1 % (docs/theory.md §7.6): a lab's handbook start is seldom within
// the few per cent of frequency a lightly damped record forgives, and a fit started out of phase
// spends its first steps raising the damping to shrink a response it cannot line up. Returns
// whether it did.
bool first_attempt(const Runner& run, RunResult& r, const std::vector<std::vector<int>>& families, bool from_ladder) {
  AttemptsContext& c = run.c;
  VectorXd start = r.initial;
  std::string label = std::string("plain ") + io::to_string(c.options.method);
  int iterations = 0;
  std::vector<RunResult::Attempt::Level> levels;
  bool spectral = false;
  if (c.problem.measured() && families.empty() && !from_ladder) {
    const SpectralStart ss = spectral_start_of(c, r.initial);
    if (ss.q.size() == r.initial.size()) {
      start = ss.q;
      label = spectral_label(c, ss);
      spectral = true;
      if (c.verbose)
        io::progress("spectral start: the model's peaks at the start x%.4g line %d of the record's up (%.6g Hz -> %.6g Hz)\n", ss.ratio,
                     ss.pairs, ss.model_hz, ss.data_hz);
    }
  }
  if (c.problem.measured() && c.problem.scenario.identification.model == io::Model::Linear) {
    r.start_check = check_start(c.problem, c.objective, start);
    if (c.verbose)
      for (const auto& w : r.start_check.warnings) io::progress("warning: %s\n", w.c_str());
  }
  if (from_ladder) {
    if (c.verbose) io::progress("%zu sections: coarse to fine from the start\n", longest(families));
    // With a prior the attempt goes on from an explained level on the full parameterization.
    std::function<void(const VectorXd&)> first_point;
    if (c.problem.scenario.identification.smoothness != 0.0)
      first_point = run_from_level(c);
    Ladder lad = coarse_to_fine(c, families, r.initial, first_point);
    start = lad.q;
    label = lad.label;
    iterations = lad.iterations;
    levels = std::move(lad.levels);
  }
  const double smoothness = c.problem.scenario.identification.smoothness;
  // Without a prior, a level that explains the data ends the attempt (with one, the prior's weight
  // is chosen on the full parameterization, from the level's estimate).
  const bool level_ends = from_ladder && smoothness == 0.0 && !levels.empty() && levels.back().explained;
  if (level_ends) {
    r.summary = explained_by_level(run, start, levels.back().blocks, longest(families));
    r.smoothness_weight = 0.0;
  } else if (smoothness >= 0.0) {
    run.header();
    c.options.smoothness_weight = smoothness;
    r.summary = run.minimize_from(start, c.options);
    r.smoothness_weight = smoothness;
  } else {
    run.header();
    r.summary = discrepancy_path(run, r, start, from_ladder && !levels.empty() && levels.back().explained, c.options);
    c.options.smoothness_weight = r.smoothness_weight;  // restarts keep the chosen prior
  }
  using A = AttemptsContext::Alongside;
  const bool explained = r.summary.termination == OptimizerSummary::Termination::DataExplained;  // cost taken
  r.fit = c.fit_at(r.summary.q, explained ? A::Nothing : families.empty() && r.summary.converged() ? A::CostAndRefits : A::Cost);
  r.attempts.push_back(attempt_record(c, label, r.summary, r.fit, iterations + r.summary.iterations_done, std::move(levels)));
  return spectral;
}

// The estimate with every sectional family smoothed once by the kernel (¼, ½, ¼) along its sections
// (the end sections reflected), in log q: a sawtooth about a smooth profile is taken out, the
// profile's trend kept.
VectorXd smoothed(const VectorXd& q, const std::vector<std::vector<int>>& families) {
  VectorXd out = q;
  for (const auto& f : families) {
    const std::size_t n = f.size();
    for (std::size_t j = 0; j < n; ++j) {
      const double a = std::log(q[f[j > 0 ? j - 1 : std::min<std::size_t>(1, n - 1)]]);
      const double b = std::log(q[f[j + 1 < n ? j + 1 : (n >= 2 ? n - 2 : 0)]]);
      out[f[j]] = std::exp(0.25 * a + 0.5 * std::log(q[f[j]]) + 0.25 * b);
    }
  }
  return out;
}

// The restarts a run may take (run_attempts): from the starting point (coarse to fine, plain, the
// cautious continuation), from the smoothed estimate of the runs so far, or from the spectral start.
enum class Restart { CoarseToFine, Plain, Smoothed, Spectral, CautiousContinuation };
const char* to_string(Restart k) {
  switch (k) {
    case Restart::CoarseToFine: return "coarse-to-fine";
    case Restart::Plain: return "plain";
    case Restart::Smoothed: return "smoothed";
    case Restart::Spectral: return "spectral";
    case Restart::CautiousContinuation: return "cautious-continuation";
  }
  return "?";
}

// One restart of kind `how` (the spectral one from `spectral`).
void restart(const Runner& run, RunResult& r, const std::vector<std::vector<int>>& families, Restart how,
             const SpectralStart& spectral) {
  AttemptsContext& c = run.c;
  OptimizerSummary s;
  int iterations = 0;
  std::string label;
  std::vector<RunResult::Attempt::Level> levels;
  if (how == Restart::CoarseToFine) {
    Ladder lad = coarse_to_fine(c, families, r.initial, run_from_level(c));
    iterations += lad.iterations;
    label = lad.label;
    levels = std::move(lad.levels);
    run.header();
    s = run.minimize_from(lad.q, c.options);
  } else if (how == Restart::Plain) {
    label = std::string("plain ") + io::to_string(c.options.method);
    run.header();
    s = run.minimize_from(r.initial, c.options);
  } else if (how == Restart::Smoothed) {
    Ladder lad = coarse_to_fine(c, families, smoothed(r.summary.q, families),
                                run_from_level(c));
    iterations += lad.iterations;
    label = "smoothed estimate, " + lad.label;
    levels = std::move(lad.levels);
    run.header();
    s = run.minimize_from(lad.q, c.options);
  } else if (how == Restart::Spectral) {
    const SpectralStart& ss = spectral;
    label = spectral_label(c, ss);
    if (c.verbose)
      io::progress("spectral start: the model's peaks at the start x%.4g line %d of the record's up (%.6g Hz -> %.6g Hz)\n", ss.ratio,
                   ss.pairs, ss.model_hz, ss.data_hz);
    run.header();
    s = run.minimize_from(ss.q, c.options);
  } else {
    const OptimizerOptions oc = cautious_continuation(c.options, c.problem.scenario.identification);
    label = cautious_continuation_label(oc);
    run.header();
    s = run.minimize_from(r.initial, oc);
  }
  iterations += s.iterations_done;
  const FitTest f = c.fit_at(s.q, s.termination == OptimizerSummary::Termination::DataExplained
                                     ? AttemptsContext::Alongside::Nothing  // its cost taken already
                                     : AttemptsContext::Alongside::Cost);
  r.attempts.push_back(attempt_record(c, label, s, f, iterations, std::move(levels)));
  c.objective.set_horizon(c.objective.data_end());
  if (better_attempt(r.attempts.back(), r.attempts[static_cast<std::size_t>(r.chosen_attempt)], c.objective.data_points())) {
    r.chosen_attempt = static_cast<int>(r.attempts.size()) - 1;
    r.summary = s;
    r.fit = f;
  }
}

}  // namespace

void run_attempts(AttemptsContext& c, RunResult& r) {
  const Problem& p = c.problem;
  const Runner run{c, Table(*p.params, p.params->names().size() <= 3 && p.params->paper_form())};
  const auto families = section_families(r.names);
  const bool from_ladder = ladder_first(p.scenario.identification, longest(families));
  const bool spectral_first = first_attempt(run, r, families, from_ladder);
  // The restarts, each tried when its condition holds, up to identification.restarts of them:
  //  - the other start of a sectional family (coarse to fine after a plain run, the plain run after
  //    the ladder: a coarse level can land in a basin the full profile does not leave — beam-ei8
  //    started coarse to fine stops at J = 0.099 where the plain run reaches 4e-8), when the residual
  //    exceeds noise and discretisation (a local minimum of a sectional profile may still fit within
  //    a declared model error) or the run used up its iterations;
  //  - the smoothed estimate of a sectional family, always without a smoothness prior (when
  //    restarts are allowed at all; it does not count against their number): a sectional profile has local minima
  //    that fit within the noise (beam-ei8 with noise 1e-4 m stops in a sawtooth 7-19 std off whose
  //    J is 2 % above the minimum near the truth — decisive between the two points, which share the
  //    noise, but within the noise's own spread of J, so no fit test can see it); coarse to fine
  //    from the estimate smoothed along its sections reaches the lower one. A prior in force
  //    penalises exactly that sawtooth (each section's step from its neighbours), so with one
  //    this restart is not run;
  //  - the spectral start (spectral_start.h), after any failure of the runs so far, when the
  //    record's dominant spectral peak and the model's at the starting point differ by more than 1 %:
  //    from the start moved so that the model's frequencies match the record's;
  //  - the cautious continuation, after any failure of the runs so far: stopped without converging
  //    (the iteration limit, a stall on a short horizon) or converged where the model does not
  //    explain the data.
  // A discrepancy principle that is not met, where the optimiser converged and the model explains
  // the data, is no such failure: a restart keeps the chosen weight and would refit the same
  // minimum; the run stays unconverged (RunResult::converged) and says why.
  // The best attempt is kept (better_attempt); where two converged attempts fit alike but differ,
  // the assessment flags the parameters they disagree on (assessment.cpp, the other-minimum test).
  std::vector<Restart> strategies;
  if (!families.empty()) strategies.insert(strategies.end(), {from_ladder ? Restart::Plain : Restart::CoarseToFine, Restart::Smoothed});
  // (after a spectral first attempt, the plain one from the stated start takes the spectral's place)
  strategies.insert(strategies.end(), {spectral_first ? Restart::Plain : Restart::Spectral, Restart::CautiousContinuation});
  int done = 0;
  SpectralStart spectral;
  auto failed = [&r]() { return !(r.summary.converged() && r.fit.explains_data); };
  for (const Restart how : strategies) {
    if (done >= p.scenario.identification.restarts) break;
    bool wanted = false;
    // (not after a level that explained the data: a blocked profile is no sawtooth to smooth)
    if (how == Restart::Smoothed)
      wanted = r.summary.q.allFinite() && r.summary.termination != OptimizerSummary::Termination::DataExplained &&
               !(r.smoothness_weight > 0.0);
    else if (how == Restart::Spectral) {
      if (failed()) spectral = spectral_start_of(c, r.initial);
      wanted = failed() && spectral.q.size() == r.initial.size();
    }
    else if (how == Restart::CautiousContinuation || (how == Restart::Plain && spectral_first)) wanted = failed();
    else
      wanted = !r.fit.within_noise_and_discretisation || r.summary.termination == OptimizerSummary::Termination::MaxIterations;
    if (!wanted) continue;
    if (c.verbose) {
      io::progress("fit test: %s\n", r.fit.message.c_str());
      if (how == Restart::Smoothed)
        io::progress("restart %d (smoothed): from the estimate smoothed along its sections — a sectional minimum may be local\n",
                    done + 1);
      else
        io::progress("restart %d (%s) from the starting point\n", done + 1, to_string(how));
    }
    restart(run, r, families, how, spectral);
    if (how != Restart::Smoothed) ++done;  // a check of every sectional run, not an answer to a failure
  }
  r.summary.cost = r.attempts[static_cast<std::size_t>(r.chosen_attempt)].cost;  // over the whole record
  if (c.verbose) io::progress("fit test: %s\n", r.fit.message.c_str());
}

}  // namespace scoleid::identify
