#pragma once
// Fixed-step diagonally implicit Runge–Kutta (ESDIRK/DIRK) stepping of the linear system
//
//     M ẍ + D ẋ + K x = F(t)
//
// that exploits its structure, for one right-hand side or several sharing every factorisation.
// Butcher table (A, b, c), s stages, taken from ARKODE (default ESDIRK3(2)4L[2]SA). In
// first-order form y = (x, v) stage i is  Y_i = y_n + h Σ_{j<i} a_ij Y'_j + h a_ii Y'_i. With
//     x̃ = x_n + h Σ_{j<i} a_ij V_j,   ṽ = v_n + h Σ_{j<i} a_ij A_j,   g = h a_ii,
// the stage unknowns V_i = ṽ + g A_i, X_i = x̃ + g V_i and the equation M A_i + D V_i + K X_i =
// F(t_n + c_i h) give
//     (M + g D + g² K) A_i = F(t_n + c_i h) − D ṽ − K (x̃ + g ṽ)
// (newton_matrix.h): one banded Cholesky solve per implicit stage, no mass-matrix inverse, no
// Newton iteration (the system is linear, so this is the stage's exact solution — the same
// numbers, to rounding, as ARKODE's ARKStep with this table, an exact Jacobian and one Newton
// iteration per stage). An explicit first stage (a_11 = 0, c_1 = 0) is y_n itself with
// acceleration a_n; step end x_{n+1} = x_n + h Σ b_j V_j, v_{n+1} = v_n + h Σ b_j A_j, and
// a_{n+1} = A_s when the table is stiffly accurate (b = last row of A, c_s = 1).
//
// Tangent systems (forward sensitivities). Columns 1..P solve
//     M s̈_i + D ṡ_i + K s_i = G_i(t, x, ẋ, ẍ),
// with G_i evaluated at column 0's own stage values (X_j, V_j, A_j). Differentiating the stage
// equations of column 0 with respect to a parameter q_i gives exactly these stage equations with
// G_i = ∂_i F − ∂_i M A_j − ∂_i D V_j − ∂_i K X_j, so the tangents are the exact derivatives of
// the discrete forward solution (not an approximation of the continuous sensitivity): a
// Gauss–Newton gradient built on them is the gradient of the discrete cost. All columns share the
// stage factorisation. Tangents stop after the first step that reaches `tangent_end`.
//
// Steps: h on every segment between breakpoints, the last step of a segment shortened to land on
// the breakpoint; at a breakpoint the left limit (forcing evaluated just before it) and the right
// limit are both recorded and stepping restarts from the right limit.
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "scoleid/identify/time/banded_cholesky.h"
#include "scoleid/identify/time/newton_matrix.h"
#include "scoleid/identify/time/stage_products.h"
#include "scoleid/identify/fe/structural_model.h"
#include "scoleid/identify/time/trajectory.h"

namespace scoleid::identify {

struct ButcherTable {
  int stages = 0;
  std::vector<double> A;  // stages × stages, row-major
  std::vector<double> b, c;
  double a(int i, int j) const { return A[static_cast<std::size_t>(i * stages + j)]; }
  bool explicit_first_stage() const;  // a_11 = 0 and c_1 = 0: stage 1 is y_n
  bool stiffly_accurate() const;      // b = last row of A and c_s = 1: y_{n+1} is the last stage
  // An ARKODE DIRK table by id (ARKODE_DIRKTableID); −1 = ESDIRK3(2)4L[2]SA.
  static ButcherTable arkode_dirk(int id = -1);
  // The id of ESDIRK4(3)6L[2]SA (Kennedy & Carpenter 2016): fourth order, L-stable, stiffly
  // accurate, explicit first stage and five implicit ones; its numerical damping on an undamped
  // mode grows as (ω h)⁵ where ESDIRK3(2)4L[2]SA's grows as (ω h)³.
  static int esdirk436_id();
  // A short name of the table with this id ("esdirk324l2sa", "esdirk436l2sa", else "arkode-dirk-<id>").
  static std::string name(int id);
};

struct StepperCounters {
  long steps = 0;
  long stage_forcings = 0;  // evaluations of F (column 0)
  long linear_solves = 0;   // banded triangular solve pairs, all columns
};

// The ends of the segments a run over [t0, t1] steps: the breakpoints inside (t0, t1), sorted and
// unique, then t1.
std::vector<double> segment_ends(const std::vector<double>& breakpoints, double t0, double t1);

// Where a run's steps are anchored within each segment between its stops: at its start (steps end
// at start + k h, the last one shortened to land on the segment's end) or at its end (steps end at
// end − k h, the first one taking the remainder). A reversed-time run (τ = T − t, the costates)
// anchored at the end steps on the forward run's grid mirrored, so that the two solutions share
// their nodes and the quadratures over both need one grid, not the union of two.
enum class StepAnchor { Start, End };

class EsdirkStepper {
public:
  using Forcing = std::function<void(double t, double* F)>;  // F (length n), pre-zeroed
  // G: n × P column-major, pre-zeroed; x, v, a: column 0 at the stage (or the recorded point).
  using TangentForcing = std::function<void(double t, const double* x, const double* v, const double* a, double* G)>;

  // M, D, K on one common pattern (newton_matrix.h); `mass` is the Cholesky factor of M.
  EsdirkStepper(const SparseMatrix& M, const SparseMatrix& D, const SparseMatrix& K, const BandedCholesky& mass,
                NewtonMatrix& newton, ButcherTable table);

  // A start other than rest (docs/theory.md §6.9): n × c, column 0 the state's x(t0) and ẋ(t0),
  // columns 1 … c − 1 the first tangents' (the others, and every column when c = 0, start at rest).
  // The accelerations follow from the equations at t0.
  struct InitialState {
    MatrixXd x, v;
  };

  struct Result {
    Trajectory state;
    std::vector<Trajectory> tangents;
    StepperCounters counters;
  };
  // Integrates from rest (or from `initial`) over [t0, t1] with step h; `stops` are the forcing
  // breakpoints (any order, those outside (t0, t1) ignored). P tangents (0 = state only) up to tangent_end.
  Result run(double t0, double t1, double h, const std::vector<double>& stops, const Forcing& forcing, int P = 0,
             const TangentForcing* tangent = nullptr, double tangent_end = 0.0,
             StepAnchor anchor = StepAnchor::Start, const InitialState* initial = nullptr) const;

  // Streaming: every recorded point goes to `sink` instead of into trajectories, so a solve needs
  // memory for one step whatever its length. The point carries what a restart needs: the step
  // grid's origin (the last breakpoint passed, or t0) and h; steps end at origin + k h.
  struct Point {
    double t = 0.0;
    int columns = 1;  // 1 + the tangents still stepped (they stop after tangent_end)
    const double *x = nullptr, *v = nullptr, *a = nullptr;  // n × columns, column-major
    double origin = 0.0, h = 0.0;
    bool resumable = true;  // false for the left limit at a breakpoint (the run goes on from the right one)
  };
  using Sink = std::function<void(const Point&)>;
  // A state (column 0 only) to resume from: a resumable Point's t, origin, h and column-0 x, v, a.
  // Resuming reproduces the original run's later points bit for bit.
  struct Start {
    double t = 0.0, origin = 0.0, h = 0.0;
    const double *x = nullptr, *v = nullptr, *a = nullptr;
  };
  // As run(), but the points go to `sink`; from rest (or `initial`) at t0 or, with `start`, from
  // start->t (then t0 is ignored, h must equal start->h, P must be 0 and `initial` null). The run
  // ends early after the first resumable point at or beyond `until` (the grid is still that of [t0, t1]).
  StepperCounters stream(double t0, double t1, double h, const std::vector<double>& stops, const Forcing& forcing,
                         const Sink& sink, int P = 0, const TangentForcing* tangent = nullptr, double tangent_end = 0.0,
                         const Start* start = nullptr, double until = std::numeric_limits<double>::infinity(),
                         StepAnchor anchor = StepAnchor::Start, const InitialState* initial = nullptr) const;

private:
  class Sweep;  // one integration's workspace and steps (esdirk_stepper.cpp)

  const SparseMatrix& M_;
  // D and K copied at construction (the Newton factors and `mass` are the caller's and must stay
  // those of the same M, D, K).
  StageProducts products_;
  const BandedCholesky& mass_;
  NewtonMatrix& newton_;
  ButcherTable tab_;
  bool explicit_first_, stiffly_accurate_;
};

}  // namespace scoleid::identify
