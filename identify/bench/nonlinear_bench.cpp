// scole-nonlinear-bench: the nonlinear SCOLE model's costs, side by side with the linear model's in
// one run (docs/theory.md §6.7), on two scenarios at the identifier's mesh and step:
//   paper-scole-1 (small pulses) and scole-slew (20° roll slew),
//   - one forward solve, linear and nonlinear, and their ratio (the price of the nonlinear model);
//   - the nonlinear gradient (forward + costate) in units of its own forward solve;
//   - the linear gradient in units of the linear forward solve, for comparison.
// Each figure is the minimum over repetitions (wall clock).
#include <algorithm>
#include <cstdio>
#include <cstdlib>

#include "best_of.h"
#include "scoleid/identify/inverse/nonlinear_objective.h"
#include "scoleid/identify/run/problem.h"

using namespace scoleid::identify;

using bench::best_of;

int main(int argc, char** argv) {
  const int reps = argc > 1 ? std::max(1, std::atoi(argv[1])) : 3;
  std::printf("scole-nonlinear-bench (wall clock, best of %d)\n\n", reps);
  std::printf("%-14s %4s %8s %11s %11s %9s %11s %9s %11s %9s\n", "scenario", "N", "step", "lin fwd [s]", "nl fwd [s]",
              "nl/lin", "nl grad [s]", "grad/fwd", "lin grad", "grad/fwd");
  for (const char* name : {"paper-scole-1", "scole-slew"}) {
    auto sc = scoleid::io::load_scenario(name);
    auto p = make_problem(sc, std::nullopt);
    const VectorXd q = p->params->initial();
    Objective lin(p->model(), *p->params, p->signals, p->data, p->objective_options);
    const ScoleNonlinear nl = scole_nonlinear(sc, p->structure->elements());
    NonlinearForwardOptions fo;
    fo.max_step = p->objective_options.solver.step;
    NonlinearObjective non(nl, *p->params, p->signals, p->data, fo);
    VectorXd g;
    const double lf = best_of(reps, [&] { lin.cost(q); });
    const double lg = best_of(reps, [&] { lin.cost_and_gradient(q, g); });
    const double nf = best_of(reps, [&] { non.cost(q); });
    const double ng = best_of(reps, [&] { non.cost_and_gradient(q, g); });
    std::printf("%-14s %4d %8.2e %11.3f %11.3f %9.1f %11.3f %9.2f %11.3f %9.2f\n", name, p->structure->elements(),
                fo.max_step, lf, nf, nf / lf, ng, ng / nf, lg, lg / lf);
    const auto& cs = non.last_costate();
    std::printf("%-14s      nonlinear forward: %ld steps, %ld f, %ld Jacobians; costate: %ld products, %ld defect "
                "iterations, %ld Jacobians\n",
                "", non.last_forward().steps, non.last_forward().rhs_evaluations, non.last_forward().jacobian_evaluations,
                cs.products, cs.defect_iterations, cs.jacobians);
  }
  return 0;
}
