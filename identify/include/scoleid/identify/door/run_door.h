#pragma once
// The identifier's front door for a run (docs/theory.md §10.0): the run's choices — the
// scenario's identification settings and the command line's (RunOptions: --method) — against
// what the problem's path offers, checked before the run's first solve:
//   - method: gauss-newton-krylov needs matrix-free Gauss–Newton products, which the nonlinear
//     model, a frequency-domain run, rate sensors (velocity, acceleration) and an estimated
//     initial state do not offer;
//   - identification.smoothness: a prior along sectional families (X_1 … X_N among the estimated),
//     of the linear model only; `discrepancy` weighs it by every sensor's stated noise;
//   - identification.start: coarse_to_fine climbs a sectional family's ladder: it needs one;
//   - a frequency-domain run takes neither a smoothness prior nor the ladder.
// Below it the run's stages take the choices as valid (a std::logic_error otherwise).
#include "scoleid/identify/run/experiments.h"
#include "scoleid/identify/run/identify_run.h"
#include "scoleid/identify/run/problem.h"

namespace scoleid::identify {

// io::InputError naming the scenario's source (or the command line's option), the field and the value.
void check_run(const Problem& p, const RunOptions& ro);
// A joint run's choices: gauss-newton-krylov (--method or the lead scenario's) needs every run's
// matrix-free products (modal data offer them).
void check_experiments_run(const ExperimentsProblem& ep, const ExperimentsOptions& eo);

}  // namespace scoleid::identify
