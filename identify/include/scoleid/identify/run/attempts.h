#pragma once
// The attempts of a linear identification run (docs/theory.md §7.6): the first attempt — plain from
// the starting values, or from the coarse-to-fine ladder over sectional parameters — with the
// smoothness prior at its given weight or chosen by the discrepancy principle (§7.8); then, when the
// fit test says the model at the estimate does not explain the data, up to identification.restarts
// more from the starting point (the other start of a sectional family, then the cautious horizon
// continuation, run/strategy.h). The best attempt (converged and explaining the data, else
// explaining it, else the lowest cost over the whole record; better_attempt) is the result.
#include <cmath>
#include <functional>
#include <optional>

#include "scoleid/identify/run/identify_run.h"

namespace scoleid::identify {

struct AttemptsContext {
  const Problem& problem;
  Objective& objective;
  OptimizerOptions options;  // the run's; the discrepancy principle leaves its chosen weight here
  bool verbose = true;
  ObjectiveCounters extra{};  // solves of the coarse-to-fine levels' own objectives
  // The iterates the current attempt's optimiser accepted so far (in the run's parameters; the
  // coarse-to-fine levels' tied ones are not kept): an interrupted run keeps the last.
  std::vector<IterationRecord> iterates;

  // The fit test at q (test_fit, identify_run.h), the last one kept: the run asks again at an
  // estimate it has just tested (a ladder level that ends the attempt, the discrepancy path's
  // plateau at its chosen weight), and each asks a forward solve on the mesh and one on the
  // doubled mesh at a quarter of the step.
  // What the test at q does on this thread while its doubled mesh is solved (test_fit's `meanwhile`;
  // nothing when the test at q is already kept): at an attempt's end, the attempt's whole-record
  // cost (attempt_cost); at one likely to stand, alongside_fit(q) too.
  // `also`: more work for this thread meanwhile (after the alongside's), when the test is taken.
  enum class Alongside { Nothing, Cost, CostAndRefits };
  FitTest fit_at(const VectorXd& q, Alongside alongside = Alongside::Nothing, const std::function<void()>& also = {});
  // The cost over the whole record at q (one state solve; INFINITY where it cannot be evaluated),
  // the last one kept.
  double attempt_cost(const VectorXd& q);
  // The coarse-to-fine ladder's screen (docs/theory.md §7.6): the fit test at q with the last
  // discretisation estimate made (fit_at's), so only the identifier's model is solved. A level it
  // fails is not explained by the mesh's error as last estimated, and the ladder goes on; a level
  // it passes is tested again with its own estimate (fit_at) before the ladder may stop there.
  // Without an earlier estimate it is fit_at. While a doubled mesh is solved this thread does what
  // likely follows (docs/theory.md §7.6): `if_not` (the next level) where there was no screen,
  // `if_explained` (the attempt's first point) where the screen passed.
  FitTest fit_screen(const VectorXd& q, const std::function<void()>& if_not = {},
                     const std::function<void()>& if_explained = {});
  VectorXd fit_q{};  // fit_at's last q and its test
  FitTest fit{};
  // Work on an estimate that is likely to stand, done while the fit test's doubled mesh is solved:
  // the first attempt's, when it converged and no restart is taken unless its fit fails (no
  // sectional family: without a prior those always get the smoothed restart). The run sets it to the assessment's
  // refits.
  std::function<void(const VectorXd&)> alongside_fit{};
  VectorXd cost_q{};  // attempt_cost's last q and its value
  double cost = INFINITY;
};

// Fills r.summary, r.fit, r.attempts, r.chosen_attempt and the smoothness fields; r.summary.cost is
// the chosen attempt's cost over the whole record.
void run_attempts(AttemptsContext& c, RunResult& r);

}  // namespace scoleid::identify
