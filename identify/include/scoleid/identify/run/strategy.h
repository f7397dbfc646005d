#pragma once
// The strategy of an identification: what the scenario's identification section and the caller's
// overrides resolve to before any solve. One place for every pipeline (a single run, the nonlinear
// model, several experiments), so `method: auto` and the optimiser's options mean the same
// everywhere (docs/theory.md §7.7).
//
// method: auto resolves by the number of parameters P and the misfit's abilities:
//   P ≤ kExplicitGaussNewtonParameters      gauss-newton (P tangent solves per iteration are cheap)
//   more, with a smoothness prior           gauss-newton up to kExplicitGaussNewtonWithPrior
//                                           parameters; beyond, gauss-newton-krylov where the misfit
//                                           offers matrix-free products (displacement sensors), else
//                                           gauss-newton
//   more, without a prior                   lbfgs
// A sectional family of more sections than the same limit starts from the coarse-to-fine ladder
// (identification.start: auto; docs/theory.md §7.6).
#include <optional>
#include <string>

#include "scoleid/identify/inverse/optimizers.h"
#include "scoleid/io/scenario.h"
#include "scoleid/io/types.h"

namespace scoleid::identify {

// More parameters than this: `auto` leaves the explicit Gauss–Newton matrix for products or
// L-BFGS, and a sectional family starts from the coarse-to-fine ladder.
inline constexpr int kExplicitGaussNewtonParameters = 16;
// With a smoothness prior, the explicit matrix up to this many parameters. Its P tangents are
// stepped in one sweep (sharing the state's factorisation and stage loops) and cost about a tenth
// of a matrix-free product each (a tangent and a costate solve of their own): measured on a beam
// of 64 elements with 64 EI sections, the whole matrix 1.07 s against 0.16 s per product; the
// truncated CG's late steps there took 4–5 s each (docs/theory.md §7.7), and stopped short of the
// minimum: the explicit step is both cheaper and exact.
inline constexpr int kExplicitGaussNewtonWithPrior = 64;

// `requested` with auto resolved (above).
io::Method resolve_method(io::Method requested, int parameters, bool smoothness_prior, bool matrix_free_products);

// The optimiser's options from the identification section: method, iteration limit (the override
// if given), tolerances, the paper's steepest-descent weights and the horizon continuation.
// steepest_weights holds one weight per parameter (io::validate_scenario refuses other counts;
// std::logic_error here).
OptimizerOptions optimizer_options(const io::IdentificationSpec& id, io::Method method, int parameters,
                                   std::optional<int> max_iterations);

// The options of the cautious restart: the same run with a horizon continuation four times as
// cautious as the scenario's (or the default's) misfit bound.
OptimizerOptions cautious_continuation(const OptimizerOptions& options, const io::IdentificationSpec& id);
// The label an attempt with those options carries in the report.
std::string cautious_continuation_label(const OptimizerOptions& options);

// Whether the first attempt starts from the coarse-to-fine ladder: identification.start says so, or
// it is auto and a sectional family has more sections than the explicit Gauss–Newton limit.
// `sections` is the longest family's length (0: none; coarse-to-fine then is refused by the door,
// identify::check_run).
bool ladder_first(const io::IdentificationSpec& id, std::size_t sections);

}  // namespace scoleid::identify
