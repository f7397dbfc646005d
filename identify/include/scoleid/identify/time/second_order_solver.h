#pragma once
// Time integration of the semi-discrete structural equation
//
//     M ẍ + D ẋ + K x = F(t),    x(t0) = 0, ẋ(t0) = 0.
//
// Three integrators:
//   esdirk (default)  ESDIRK3(2)4L[2]SA (Kennedy & Carpenter; ARKODE's table): 3rd order,
//                     L-stable, 4 stages, fixed step h, stepped by esdirk_stepper.h, which exploits
//                     the linear second-order structure (one banded solve per implicit stage). A
//                     point load excites every mode of the mesh; the modes with ω h ≫ 1 are the ones
//                     the mesh represents worst, and an L-stable method damps their oscillation
//                     (keeping their quasi-static part) instead of tracking it with ~ω_max·T steps.
//                     The step is min(sample interval, 0.3/ω_K), ω_K the highest mode the data
//                     contain (problem.h, data_content); the method is
//                     third order, so the time error is O(h³) in the resolved band.
//   esdirk-arkode     the same table and step through SUNDIALS ARKODE (ARKStep) on the first-order
//                     form y = [x; v], ẋ = v, v̇ = M⁻¹ (F(t) − D v − K x): the reference the stepper
//                     is checked against (same numbers to rounding).
//   bdf               CVODES variable-order BDF with error control at rtol: the adaptive
//                     reference (it must resolve every excited mode, so it is far slower on
//                     undamped structures; see the benchmark).
// The SUNDIALS Newton systems (I − γJ) [a; b] = [r1; r2] are solved through the structure of J
// instead of forming the dense M⁻¹K:
//     (M + γD + γ²K) b = M r2 − γ K r1,    a = r1 + γ b,
// with the banded Cholesky of newton_matrix.h (so Newton is exact for this linear ODE). This is a
// matrix-embedded SUNLinearSolver.
//
// The same solver runs the state forward, the costate backward (in reversed time τ = T − t the
// costate equation M p̈ − D ṗ + K p = g becomes M P'' + D P' + K P = g, P(τ) = p(T − τ)) and the
// forward sensitivities; with esdirk the sensitivities (tangents) are stepped together with the
// state on its own stages (solve_tangent), sharing every factorisation. Forcing discontinuities
// are passed as breakpoints: the integrator stops there and restarts, recording left and right
// limits.
//
// Error weights (bdf, and the ARKODE Newton test): w_i = 1/(rtol |y_i| + atol_g), atol_g = rtol ·
// max(largest |y_j| seen so far in y_i's group, the group's reference scale). DOFs of like units
// (displacements, rotations, their rates) share a group; the reference scale is the quasi-static
// response to the largest forcing (see reference_scales), so no absolute tolerance has to be
// guessed by the user.
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "scoleid/identify/fe/structural_model.h"
#include "scoleid/identify/time/esdirk_stepper.h"
#include "scoleid/identify/time/trajectory.h"
#include "scoleid/io/types.h"

namespace scoleid::identify {

struct SolverOptions {
  using Integrator = io::Integrator;  // identification.integrator
  Integrator integrator = Integrator::Esdirk;
  double step = 0.0;           // esdirk: fixed step; 0 = (t1 − t0)/2000
  int dirk_table = -1;         // esdirk, esdirk-arkode: ARKODE DIRK table id; −1 = ESDIRK3(2)4L[2]SA
  double rtol = 1e-9;
  double atol_floor = 1e-280;  // absolute floor of the group scales (only matters for zero forcing)
  long max_steps = 2000000;
  double max_step = 0.0;       // 0 = unlimited
  int max_order = 5;
  double velocity_scale = 1.0;  // bdf: velocity reference scale multiplier
  bool IsValid(std::string* why) const;
};

struct SolverSummary {
  bool ok = false;
  std::string message;
  long steps = 0;
  long rhs_evaluations = 0;
  long factorizations = 0;
  long linear_solves = 0;
  long error_test_failures = 0;
  long nonlinear_iterations = 0;
  double wall_seconds = 0.0;
  std::string BriefReport() const;
  void Accumulate(const SolverSummary& other);
};

class SecondOrderSolver {
public:
  using Forcing = std::function<void(double t, double* F)>;  // fills F (length n), pre-zeroed

  SecondOrderSolver(const SparseMatrix& M, const SparseMatrix& D, const SparseMatrix& K, std::vector<int> dof_group,
                    SolverOptions options = {});
  ~SecondOrderSolver();
  SecondOrderSolver(const SecondOrderSolver&) = delete;
  SecondOrderSolver& operator=(const SecondOrderSolver&) = delete;

  int dim() const;
  // A start other than rest (esdirk only; the other integrators throw std::logic_error when given
  // one): column 0 the state's x(t0), ẋ(t0), further columns the first tangents' (esdirk_stepper.h).
  using InitialState = EsdirkStepper::InitialState;
  // Integrates over [t0, t1] from rest (or `initial`). Throws std::runtime_error if CVODES fails. `anchor`
  // (esdirk; the other integrators choose their own steps): where the fixed steps are anchored in
  // each segment between breakpoints (esdirk_stepper.h; End for reversed-time costate runs).
  Trajectory solve(double t0, double t1, const Forcing& forcing, const std::vector<double>& breakpoints,
                   SolverSummary* summary = nullptr, StepAnchor anchor = StepAnchor::Start,
                   const InitialState* initial = nullptr) const;
  // State and P tangents stepped together (esdirk only; see esdirk_stepper.h):
  //   M s̈_i + D ṡ_i + K s_i = G_i(t, x, ẋ, ẍ) at the state's own stage values.
  // The state is integrated over [t0, t1], the tangents up to the first step end >= tangent_end.
  // Throws std::logic_error for the other integrators.
  using TangentForcing = std::function<void(double t, const double* x, const double* v, const double* a, double* G)>;
  struct TangentSolution {
    Trajectory state;
    std::vector<Trajectory> tangents;
  };
  bool has_tangent_solve() const;
  TangentSolution solve_tangent(double t0, double t1, const Forcing& forcing, int P, const TangentForcing& tangent,
                                double tangent_end, const std::vector<double>& breakpoints,
                                SolverSummary* summary = nullptr, StepAnchor anchor = StepAnchor::Start,
                                const InitialState* initial = nullptr) const;
  // Streaming solves: every recorded point goes to `sink` and nothing is stored, so the memory is
  // that of one step (esdirk_stepper.h, Point). With esdirk a run can resume from a recorded
  // resumable point (`start`, state only) and end early at `until`, reproducing the original run's
  // points bit for bit: the basis of checkpointing (objective.h). The other integrators stream a
  // stored solution and cannot resume (can_resume() is false; `start` then throws logic_error).
  using Point = EsdirkStepper::Point;
  using Sink = EsdirkStepper::Sink;
  using Start = EsdirkStepper::Start;
  bool can_resume() const { return has_tangent_solve(); }
  void stream(double t0, double t1, const Forcing& forcing, const std::vector<double>& breakpoints, const Sink& sink,
              SolverSummary* summary = nullptr, const Start* start = nullptr,
              double until = std::numeric_limits<double>::infinity(), StepAnchor anchor = StepAnchor::Start,
              const InitialState* initial = nullptr) const;
  // State and P tangents streamed together (esdirk only, as solve_tangent).
  void stream_tangent(double t0, double t1, const Forcing& forcing, int P, const TangentForcing& tangent,
                      double tangent_end, const std::vector<double>& breakpoints, const Sink& sink,
                      SolverSummary* summary = nullptr, StepAnchor anchor = StepAnchor::Start,
                      const InitialState* initial = nullptr) const;
  // ẍ = M⁻¹ (F − D v − K x)
  void acceleration(const double* F, const double* x, const double* v, double* a) const;

  struct Impl;  // CVODES state; public only so the C callbacks can name it

private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace scoleid::identify
