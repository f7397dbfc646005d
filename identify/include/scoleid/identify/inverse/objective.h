#pragma once
// The identification functional and its derivatives (docs/theory.md §6, paper Eqs. 18–25).
//
//   state     M ü + D u̇ + K u = Σ_i γ_i b_i f_i(t),           u(0) = u̇(0) = 0
//   cost      J(q) = ½ ∫₀ᵀ rᵀ R r dt,   r = C₀ u + C₁ u̇ + C₂ ü − z̃(t)   (rows on displacements,
//             velocities and accelerations; ü = M⁻¹(f − D u̇ − K u) from the equation of motion at
//             each quadrature point, so r = (C₀ − C₂M⁻¹K) u + (C₁ − C₂M⁻¹D) u̇ + C₂M⁻¹f − z̃)
//   costate   M p̈₀ − D ṗ₀ + K p₀ = −w₀,   w₀ = C₀ᵀ R r − K μ,   p₀(T) = ṗ₀(T) = 0   (Eqs. 23–24)
//             M ÿ − D ẏ + K y = −w₁,      w₁ = C₁ᵀ R r − D μ,   y(T) = ẏ(T) = 0
//             μ = M⁻¹ C₂ᵀ R r;  multiplier p = p₀ − ẏ − μ   (docs/theory.md §6.1a; y and μ only with
//             velocity or acceleration sensors, otherwise p = p₀, w₀ = C₀ᵀ R r).
//             Both integrated backward as P(τ) = p₀(T − τ), Y(τ) = y(T − τ):
//             M P'' + D P' + K P = −w₀(T − τ), likewise Y; −ẏ(t) = Y'(T − t). With the esdirk
//             integrator Y is stepped with P on P's stages (one pass, shared factorisations).
//   gradient  ∂J/∂q_i = ∫₀ᵀ pᵀ (∂_i M ü + ∂_i D u̇ + ∂_i K u − ∂_i B f) dt                (Eq. 25)
//             evaluated per model coefficient c_j and chained through ∂c/∂q. Without rate sensors
//             the mass term is integrated by parts, ∫ pᵀ M_j ü dt = −∫ ṗᵀ M_j u̇ dt (p(T) = 0,
//             u̇(0) = 0), so only displacements and velocities of the two recorded solutions
//             enter; with them p(T) = −μ(T) ≠ 0 and ü is taken from the equation of motion.
//             Either way the cost is one forward and one backward pass, independent of P.
//   Gauss–Newton (in blocks of parameters, see kSensitivityBlockBytes): sensitivities S_i = ∂u/∂q_i from
//             M S̈_i + D Ṡ_i + K S_i = −(∂_i M ü + ∂_i D u̇ + ∂_i K u − ∂_i B f),
//             H = ∫ (C S)ᵀ R (C S) dt,  g = ∫ (C S)ᵀ R r dt.
//             With the esdirk integrator the S_i are stepped with u on u's own stages
//             (esdirk_stepper.h): the exact derivatives of the discrete u, one factorisation for
//             all; otherwise each is integrated on its own with u interpolated.
// All time integrals use 3-point Gauss–Legendre on every interval of the union of the solvers'
// steps and the sample times, on the Hermite interpolants of the recorded solutions; with
// displacement sensors the costate gradient's coefficient integrand (Eq. 25's n-long part) takes
// the 2-point rule on the intervals of the steps alone (docs/theory.md §6.4).
// R is diagonal; by default R_kk = 1 / ((T − t0) · mean z_k²) over the samples in [t0, T], so J is
// the relative mean-square misfit.
//
// Horizon: T may be set below the end of the data (set_horizon); cost, gradient and Gauss–Newton
// matrix are then those of the data on [t0, T] (with the default weights recomputed on it).
// Gauss–Newton can also return the misfit profile of its state solve over the whole data span:
// per sample time t_i, the mean over sensors of ∫_{t0}^{t_i} r_k² dt / ∫_{t0}^{t_i} z̃_k² dt, the
// relative mean-square misfit of the data on [t0, t_i] (used to choose the horizon, optimizers.h).
#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "scoleid/identify/inverse/measurements.h"
#include "scoleid/identify/inverse/misfit.h"
#include "scoleid/identify/inverse/parameterization.h"
#include "scoleid/identify/time/add_members.h"
#include "scoleid/identify/time/checkpoints.h"
#include "scoleid/identify/time/second_order_solver.h"
#include "scoleid/identify/fe/structural_model.h"
#include "scoleid/io/signal.h"

namespace scoleid::identify {

// Memory for recorded sensitivity trajectories at once: Gauss–Newton and the output sensitivities
// step the P tangents in blocks that fit in it (the state re-solved with each block), so memory
// does not grow with steps × DOFs × P.
inline constexpr double kSensitivityBlockBytes = 128.0 * 1024 * 1024;
// A recorded state longer than this is checkpointed in the gradient (every sensor kind) and the
// Gauss–Newton products (displacement sensors: the only ones they take), and the interpolation
// misfit streams it (time/checkpoints.h, docs/theory.md §7.9); esdirk only.
inline constexpr double kTrajectoryBytes = 32.0 * 1024 * 1024;

// The default coarsening of the step matrix's time step (ObjectiveOptions::step_matrix_coarsening).
// The matrix only shapes the steps; its tangents' time error grows as (ω h)^p, and four times the
// step keeps it a few 10⁻³ of the matrix on a 64-section beam (docs/theory.md §7.2).
inline constexpr double kStepMatrixCoarsening = 4.0;

struct ObjectiveOptions {
  SolverOptions solver;
  double sensitivity_block_bytes = kSensitivityBlockBytes;
  double trajectory_bytes = kTrajectoryBytes;
  // Checkpoint spacing L in recorded points: 0 = automatic (√(points/3) when the state exceeds
  // trajectory_bytes, else the whole state is stored); > 0 = always checkpoint every L points.
  long checkpoint_points = 0;
  std::vector<double> weights;  // R_kk; empty = 1/(T mean z_k²)
  // Each sensor's stated noise level (<= 0 or absent: unknown). The misfit profile of the horizon
  // continuation (MisfitProfile) counts only what exceeds the noise's expected share (below).
  std::vector<double> noise_std;
  // The share of the samples that are independent: 1 for white noise; g = Σh² for data filtered
  // to a band (band_filter.h), whose noise the interpolant follows (E∫ñ² = σ²(t − t0)) and whose
  // ∫ñ² varies about 1/g times as much.
  double noise_independent_fraction = 1.0;
  // Threads of one Gauss–Newton sweep or output-sensitivity pass (esdirk, no acceleration sensors,
  // two or more parameters): the tangents split in two groups, each stepped with its own copy of
  // the state on its own thread (docs/theory.md §7.9). 0 = automatic (two when the machine has
  // two hardware threads), 1 = one thread (callers that already run objectives side by side).
  int sweep_threads = 0;
  // The optimiser's step matrix (gradient_and_step_matrix, docs/theory.md §7.2): tangents on this
  // many times the solver's step (esdirk, fixed step; never beyond the data's mean sample
  // interval), J and g on the solver's own. 1 = the same step (gradient_and_step_matrix is then
  // gauss_newton).
  double step_matrix_coarsening = kStepMatrixCoarsening;
  // The initial state (docs/theory.md §6.9): 0 (the default) for a structure at rest at the first
  // sample; m > 0 for a state in the model's m lowest modes at the parameterization's initial
  // values (B, M-orthonormal, n × m): x(t0) = B a and ẋ(t0) = B b, the 2m coefficients (a, b)
  // eliminated at every q. The outputs are affine in them, so they take their least-squares values
  // there (variable projection), and cost, gradient, Gauss–Newton matrix and output sensitivities
  // are those of the parameters with the initial state profiled out: the matrix and the
  // sensitivities are projected off the initial state's directions, so the Fisher information and
  // the intervals count its unknowns. esdirk only.
  int initial_state_modes = 0;
};

struct ObjectiveCounters {
  long forward_solves = 0;
  long costate_solves = 0;
  long sensitivity_solves = 0;
  long gradient_evaluations = 0;
  double forward_seconds = 0.0;
  double costate_seconds = 0.0;
  double sensitivity_seconds = 0.0;
  double quadrature_seconds = 0.0;
  long checkpointed_passes = 0;   // gradients and products whose state was checkpointed
  long checkpoint_resolves = 0;   // state segments re-solved from checkpoints
  SolverSummary solver;  // accumulated over all solves
  // Adds another objective's counts and times (the tied levels of coarse to fine).
  void Accumulate(const ObjectiveCounters& o) {
    using C = ObjectiveCounters;
    add_members(*this, o, &C::forward_solves, &C::costate_solves, &C::sensitivity_solves, &C::gradient_evaluations,
                &C::forward_seconds, &C::costate_seconds, &C::sensitivity_seconds, &C::quadrature_seconds,
                &C::checkpointed_passes, &C::checkpoint_resolves);
    solver.Accumulate(o.solver);
  }
};

class Objective : public Misfit {
public:
  Objective(const StructuralModel& model, const Parameterization& params, std::vector<io::Signal> inputs,
            Measurements data, ObjectiveOptions options = {});

  int size() const override { return params_.size(); }
  double horizon() const override { return T_; }
  double data_start() const override { return data_.t.front(); }
  // The first sample at which an input exceeds a twentieth of its peak, when the record's quiet
  // start before it is more than 5 % of the record (a lab's pre-trigger: horizons from the record's
  // start would spend their first length on the model's rest); else data_start().
  double response_start() const override { return response_start_; }
  double data_end() const override { return data_.t.back(); }
  // Restricts the cost to [t0, T] (clamped to the data span, at least two samples); T = data_end()
  // restores the whole span.
  void set_horizon(double T) override;
  // Number of data values (samples × sensors) on the horizon.
  long data_points() const override;

  const Parameterization& parameterization() const { return params_; }
  const StructuralModel& model() const { return model_; }
  const std::vector<double>& weights() const { return R_; }

  // J(q): one forward solve.
  double cost(const VectorXd& q) override;
  // J and ∂J/∂q by the costate: one forward and one backward solve (two backward equations with
  // velocity or acceleration sensors, stepped together by esdirk), whatever the number of parameters.
  double cost_and_gradient(const VectorXd& q, VectorXd& gradient) override;
  double recalled_cost_and_gradient(const VectorXd& q, VectorXd& gradient) override;
  // J, g = ∂J/∂q and the Gauss–Newton matrix H from P forward-sensitivity solves. With `profile`
  // the state is integrated over the whole data span and its misfit profile returned. The last
  // evaluation without a profile is kept: asked again at the same q on the same horizon (an
  // optimiser run continuing from where the previous one ended), it is returned without a solve.
  double gauss_newton(const VectorXd& q, VectorXd& gradient, MatrixXd& H, MisfitProfile* profile = nullptr) override;
  // J and g = ∂J/∂q by the costate on the solver's step, H from P tangents on the coarser step of
  // options.step_matrix_coarsening (a copy of this objective at that step, on the same horizon):
  // the matrix shapes the optimiser's steps, J and g fix its minimum (docs/theory.md §7.2). Where
  // the coarser step is not longer (no fixed esdirk step, or capped at the sample interval), this is
  // gauss_newton. The last evaluation is kept like gauss_newton's.
  double gradient_and_step_matrix(const VectorXd& q, VectorXd& gradient, MatrixXd& H) override;
  // The time step of gradient_and_step_matrix's tangents (the solver's where no coarser one applies).
  double step_matrix_step() const;
  // step_matrix_step() is longer than the solver's: the matrix is its own evaluation.
  bool has_separate_step_matrix() const override;
  // gradient_and_step_matrix's H alone (gauss_newton's where it is not separate).
  void step_matrix(const VectorXd& q, MatrixXd& H) override;
  // The misfit profile over the whole data span at q (one forward solve).
  MisfitProfile misfit_profile(const VectorXd& q) override;
  // ∂J/∂q by central differences with relative step h (2P forward solves).
  VectorXd finite_difference_gradient(const VectorXd& q, double h = 1e-5);
  // Model outputs C u(t_i) at the sample times (samples × sensors).
  MatrixXd predict(const VectorXd& q);
  // ½ Σ_k R_k ∫ (y_k − ỹ_k)² dt over [t0, T] at q: y the model's output, ỹ the cubic interpolant of
  // its own samples (measurements.h). The part of the cost sampling alone leaves whatever the
  // parameters and the noise: data that the model fits exactly still differ from the model between
  // samples by the interpolant's error (docs/theory.md §7.8). One stored forward solve, or two
  // streamed ones above the trajectory budget.
  double interpolation_misfit(const VectorXd& q);
  // Output sensitivities ∂(C u(t_i))/∂q at the sample times: (samples·sensors) × P, row-major by
  // sample. For Fisher information. A Gauss–Newton evaluation on the whole record (esdirk, no
  // acceleration sensors, within sensitivity_block_bytes) keeps its own at its q: asked at that
  // same q, they are returned without a solve (the same numbers: one interpolation for both).
  MatrixXd output_sensitivities(const VectorXd& q);
  // A direction of the operators that no parameter spans: ∂K = k w wᵀ, ∂D = d w wᵀ (with w = Mφ of a
  // mass-normalised mode φ, one mode's stiffness or damping alone: the record's own modes,
  // inverse/record_modes.h).
  struct RankOneDirection {
    VectorXd w;
    double d = 0.0, k = 0.0;
  };
  // As output_sensitivities, with one more column per direction after the parameters' (one pass
  // of P + extra tangents; never kept). Empty where it cannot be formed (an estimated initial
  // state without the esdirk tangents).
  MatrixXd output_sensitivities_with(const VectorXd& q, const std::vector<RankOneDirection>& extra);
  // The Gauss–Newton matrix times v without forming it (docs/theory.md §7.7): one tangent solve
  // along v (with the state) and one costate solve whose source is the tangent's output C S v in
  // place of the residual; the gradient formula (Eq. 25) on that costate is H v. Two solves
  // whatever the number of parameters. Displacement sensors only (has_matrix_free_products()).
  VectorXd gauss_newton_product(const VectorXd& q, const VectorXd& v) override;
  bool has_matrix_free_products() const override { return C1_.size() == 0 && !estimates_initial_state(); }

  // Whether the initial state is estimated (ObjectiveOptions::initial_state_basis), and its
  // least-squares coefficients (a, b) at q (one pass of 2m tangents).
  bool estimates_initial_state() const { return basis_.cols() > 0; }
  const MatrixXd& initial_state_basis() const { return basis_; }

  // The basis modes' angular frequencies at the start values [rad/s] (rigid-body modes ≈ 0).
  const VectorXd& initial_state_omega() const { return basis_omega_; }
  VectorXd initial_state_coefficients(const VectorXd& q);

  const ObjectiveCounters& counters() const { return counters_; }
  void reset_counters() { counters_ = {}; }

  // The forcing f_i(t) of every input at t (for reports and the CVODES cross-check).
  double input(int i, double t) const { return inputs_[static_cast<std::size_t>(i)](t); }
  const std::vector<double>& breakpoints() const { return breakpoints_; }
  const Measurements& data() const { return data_; }

private:
  struct Setup {
    VectorXd c;
    MatrixXd dcdq;
    AssembledModel ops;
    // The state at the first sample (null: rest) and its coefficients (a, b) in the basis.
    std::shared_ptr<const SecondOrderSolver::InitialState> initial;
    VectorXd initial_coefficients;
  };
  Setup setup(const VectorXd& q) const;
  Trajectory forward(const SecondOrderSolver& solver, const Setup& s, double t_end);
  // The state streamed over [t0, t_end] in windows of kStreamWindow points (checkpoints.h), each
  // handed to `visit`: memory O(window · DOF) whatever the record's length.
  static constexpr std::size_t kStreamWindow = 256;
  void forward_windows(const SecondOrderSolver& solver, const Setup& s, double t_end, const WindowedSink::Visit& visit);
  // The quadrature grid on a window: its times ∪ the sample times ∪ {t_end}, within [t0, t_end].
  void window_grid(const Trajectory& w, double t_end, std::vector<double>& grid) const;
  // ½ Σ_k R_k ∫ (y_k − z̃_k)² over the window's part of [t0, t_end].
  double misfit_window(const Setup& s, const SecondOrderSolver& solver, const Trajectory& w, const Measurements& z,
                       double t_end) const;
  struct ProfileSums;
  void profile_window(const Setup& s, const SecondOrderSolver& solver, const Trajectory& w, ProfileSums& sums) const;
  // ½ Σ_k R_k ∫ (y_k − z̃_k)² over [t0, T] against the interpolant of `z` (the data, or other samples).
  double misfit_against(const Setup& s, const SecondOrderSolver& solver, const Trajectory& u, const Measurements& z) const;
  MisfitProfile misfit_profile(const Setup& s, const SecondOrderSolver& solver, const Trajectory& u) const;
  // Outputs at t from the state (x, v): C_0 x + C_1 v + C_2 a, a from the equation of motion
  // (returned through `a` when a sensor reads it).
  struct Derivative;
  VectorXd output_at(const Setup& s, const SecondOrderSolver& solver, double t, const VectorXd& x, const VectorXd& v,
                     VectorXd* a = nullptr) const;
  // Output sensitivity at t: C_0 S + C_1 Ṡ + C_2 S̈, S̈ from the sensitivity equation.
  VectorXd tangent_output_at(const SecondOrderSolver& solver, const Derivative& d, double t, const VectorXd& x,
                             const VectorXd& v, const VectorXd& a, const VectorXd& si, const VectorXd& svi) const;
  std::vector<double> reversed_breakpoints() const;
  // Union of the given time sets and the sample times (without `samples`: t0 alone), restricted
  // to [t0, t_end].
  std::vector<double> union_grid(const std::vector<const std::vector<double>*>& sets, double t_end,
                                 bool samples = true) const;
  SecondOrderSolver::Forcing state_forcing(const Setup& s) const;
  // ∂_i M, ∂_i D, ∂_i K and ∂_i b per input, for the sensitivity forcing.
  struct Derivative {
    SparseMatrix dM, dD, dK;
    std::vector<VectorXd> db;
    VectorXd x0, v0;  // the tangent's start (empty: rest), for the initial state's directions
    RankOneDirection rank_one;  // added to ∂D and ∂K (empty w: none)
  };
  Derivative derivative(const Setup& s, int i) const;
  // Σ_j dc_j ∂M/∂c_j etc.: the derivative along a direction dc of the model coefficients.
  Derivative derivative_along(const VectorXd& dc) const;
  // With an estimated initial state: its least-squares coefficients at s's parameters into s (a
  // pass from rest with the 2m initial-state tangents), so that every later solve on s starts there.
  void settle_initial_state(Setup& s, const SecondOrderSolver& solver);
  // The 2m initial-state directions as tangents: no operator derivative, x(t0) = B_j or ẋ(t0) = B_j.
  std::vector<Derivative> initial_state_derivatives() const;
  // The start of a run of the state and the tangents d: column 0 s.initial, then each tangent's own
  // (null when all start at rest).
  std::unique_ptr<SecondOrderSolver::InitialState> run_start(const Setup& s, const std::vector<Derivative>& d) const;
  // p(t0)ᵀ M_j ẋ(t0) of the mass term taken by parts (Eq. 25 with displacement sensors) when the
  // state starts moving: subtracted from gc (docs/theory.md §6.9).
  void add_initial_velocity_term(const Setup& s, const VectorXd& p0, VectorXd& gc) const;
  // G's columns projected off the initial state's (the last 2m), in the Fisher information's
  // weights (each sensor's stated noise, else R): (samples·sensors) × P.
  // (leading ≥ 0: G's first `leading` columns are projected, the rest are the initial state's.)
  MatrixXd project_initial_state(const MatrixXd& G, int leading = -1) const;
  // The output sensitivities of the tangents d (the last ones may be the initial state's, after the
  // first `leading`), streamed with the state in one pass, projected off the initial state's.
  MatrixXd streamed_output_sensitivities(const Setup& s, const SecondOrderSolver& solver, const std::vector<Derivative>& d,
                                         int leading);
  Trajectory sensitivity(const SecondOrderSolver& solver, const Setup& s, const Trajectory& u, const Derivative& d,
                         double t_end) const;
  // The tangents' forcing G_i = −(∂_i M ü + ∂_i D u̇ + ∂_i K u − ∂_i B f) for the given derivatives
  // (copied: the returned function does not refer to `d`).
  SecondOrderSolver::TangentForcing tangent_forcing(const std::vector<Derivative>& d) const;
  // The state and the tangents of the given derivatives (as solve_with_sensitivities).
  std::vector<Trajectory> solve_tangents(const SecondOrderSolver& solver, const Setup& s, double state_end,
                                         double tangent_end, Trajectory& u, const std::vector<Derivative>& d);
  // Adds the input coefficients' share of ∂J/∂c (Eq. 25) at a quadrature point of weight wt.
  void add_input_gradient(double t, double wt, const VectorXd& p, VectorXd& gc) const;
  // The state over [t0, state_end] and the sensitivities to parameters first … first + count − 1
  // (count < 0: to the last) over [t0, tangent_end] (tangent_end <= state_end).
  std::vector<Trajectory> solve_with_sensitivities(const SecondOrderSolver& solver, const Setup& s, double state_end,
                                                   double tangent_end, Trajectory& u, int first = 0, int count = -1);
  // How many sensitivity trajectories over [t0, t_end] fit in options.sensitivity_block_bytes (at
  // least 1, at most P).
  int sensitivity_block(double t_end) const;
  void default_weights();
  // [a, b] cut at the sample times strictly inside it (a and b included); `next`, left at the first sample
  // above a, only moves forward, so consecutive intervals walk the samples once.
  void interval_cuts(double a, double b, std::size_t& next, std::vector<double>& cuts) const;
  // Gauss–Newton with all tangents streamed (esdirk): g, H, J accumulated on the fly; with
  // `sample_rows` (horizon = the whole record, no acceleration sensors) also the output
  // sensitivities at the sample times, as output_sensitivities returns them.
  // `derivs`: the tangents (default: the P parameters').
  double gauss_newton_streamed(const Setup& s, const SecondOrderSolver& solver, double state_end, VectorXd& gradient,
                               MatrixXd& H, MisfitProfile* profile, MatrixXd* sample_rows = nullptr,
                               const std::vector<Derivative>* derivs = nullptr);
  // gauss_newton_solve with the initial state estimated (its coefficients profiled out of g and
  // H), and without a tangent stepper (the tangents in blocks, each with the state re-solved).
  double gauss_newton_with_start(const Setup& s, const SecondOrderSolver& solver, double state_end, VectorXd& gradient,
                                 MatrixXd& H, MisfitProfile* profile);
  double gauss_newton_blocked(const Setup& s, const SecondOrderSolver& solver, double state_end, VectorXd& gradient,
                              MatrixXd& H, MisfitProfile* profile);
  // Its two passes, each adding every interval between recorded points to the running sums: on the
  // outputs (no acceleration sensors; stream_outputs, and the sample rows), or on the states.
  struct StreamPass;
  void stream_output_pass(const Setup& s, const SecondOrderSolver& solver, double state_end, const std::vector<Derivative>& d,
                          const SecondOrderSolver::Sink& state_visit, MatrixXd* sample_rows, StreamPass& pass,
                          SolverSummary& sum) const;
  void stream_state_pass(const Setup& s, const SecondOrderSolver& solver, double state_end, const std::vector<Derivative>& d,
                         WindowedSink* profile_sink, StreamPass& pass, SolverSummary& sum) const;
  // cost_and_gradient's two ways into gc (the coefficient gradient): the state checkpointed every
  // L points, or stored whole, each with its backward pass.
  double gradient_checkpointed(const Setup& s, const SecondOrderSolver& solver, std::size_t L, VectorXd& gc);
  double gradient_stored(const Setup& s, const SecondOrderSolver& solver, VectorXd& gc);
  // Rate sensors (docs/theory.md §6.1a): with ü = M⁻¹(f − D u̇ − K u) the residual is
  //   r = A₀ u + A₁ u̇ + Σ_i f_i G_i − z̃,   A₀ = C₀ − C₂M⁻¹K,  A₁ = C₁ − C₂M⁻¹D,  G_i = C₂M⁻¹b_i,
  // dense ns × n, and μ = M⁻¹C₂ᵀ R r = (M⁻¹C₂ᵀ) R r: ns mass solves per gradient, none per forcing.
  struct RateTerms {
    MatrixXd A0, A1, MinvC2t, G;
  };
  RateTerms rate_terms(const Setup& s, const SecondOrderSolver& solver) const;
  // The costates' sources and what Eq. 25 takes from the costates (objective.cpp): displacement
  // sensors (one costate) or rate sensors (two).
  class CostateSources;
  class DisplacementSources;
  class RateSources;
  // The checkpoint spacing for a state over [t0, T] with this solver; 0 = store the whole state.
  std::size_t checkpoint_spacing(const SecondOrderSolver& solver) const;
  // The backward pass on a checkpointed state (docs/theory.md §7.9): the costates of `src` streamed
  // in windows, and the Eq. 25 quadrature into gc with the state re-solved from `ckpts`. Returns
  // ½ Σ_k R_k ∫ r_k² when the sources carry the residual (else 0).
  double backward_checkpointed(const Setup& s, const SecondOrderSolver& solver, CostateSources& src,
                               std::vector<Checkpoint> ckpts, std::size_t spacing, VectorXd& gc);
  // The backward pass on a stored state u (docs/theory.md §6.2): the costates of `src` whole, then
  // the quadrature on every interval of the union of the state's, the costates', the samples' and
  // `more_times`. Returns as backward_checkpointed.
  double backward_stored(const Setup& s, const SecondOrderSolver& solver, const Trajectory& u, CostateSources& src,
                         const std::vector<double>& more_times, VectorXd& gc);
  // The costates of `src` over the whole record: P, and Y for rate sensors.
  void costates_stored(const SecondOrderSolver& solver, CostateSources& src, Trajectory& P, Trajectory& Y);
  // A costate window W (in τ) as t in [ta, tb]: the state re-solved over it (time added to
  // resolve_seconds) and its quadrature grid (W's times, the state's and the samples', sorted and
  // unique); `steps` (if not null): the same without the samples. False when the window holds no
  // time of the data.
  bool cover_window(const Trajectory& W, CheckpointedState& state, std::vector<double>& grid, std::vector<double>* steps,
                    double& resolve_seconds) const;


  const StructuralModel& model_;
  const Parameterization& params_;
  std::vector<io::Signal> inputs_;
  Measurements data_;
  ObjectiveOptions options_;
  MatrixXd basis_;        // the initial state's modes (n × m; empty: rest)
  VectorXd basis_omega_;  // their angular frequencies at the start values
  MatrixXd C_;            // rows on u
  Eigen::SparseMatrix<double, Eigen::RowMajor> Cs_;  // the nonzeros of C_ (a sensor reads a few dofs)
  MatrixXd C1_, C2_;      // rows on u̇ and ü (empty without velocity or acceleration sensors)
  bool accelerations_ = false;
  std::vector<double> R_;
  std::vector<double> breakpoints_;
  // The stated noise's share of the misfit profile: per sensor σ_k², and per sample time t_i the
  // expected ∫ñ² of unit white noise over [t0, t_i] (W_i) and that plus two of its standard
  // deviations (B_i). Empty without stated noise.
  struct NoiseShare {
    VectorXd sigma2;
    std::vector<double> W, B;
  };
  NoiseShare noise_;
  void noise_share();  // noise_ from options_.noise_std and the sample times
  void make_initial_state_basis();  // basis_ and basis_omega_ (options_.initial_state_modes > 0)
  double T_ = 0.0;  // horizon: end of the cost integral
  double response_start_ = 0.0;
  ObjectiveCounters counters_;
  // The last whole-record Gauss–Newton evaluation's output sensitivities and its q (empty q: none).
  struct KeptSensitivities {
    VectorXd q;
    MatrixXd G;
  };
  KeptSensitivities kept_;
  // The last Gauss–Newton evaluation without a profile (gauss_newton): q (empty: none), horizon, J, g, H.
  struct LastGaussNewton {
    VectorXd q;
    double T = 0.0;
    double J = 0.0;
    VectorXd g;
    MatrixXd H;
    // Kept for this q and horizon: g and H copied out, J returned.
    bool recall(const VectorXd& at, double horizon, double& J_out, VectorXd& g_out, MatrixXd& H_out) const {
      if (q.size() != at.size() || q != at || T != horizon) return false;
      J_out = J;
      g_out = g;
      H_out = H;
      return true;
    }
  };
  LastGaussNewton last_gn_;
  LastGaussNewton last_step_;  // gradient_and_step_matrix's, when its matrix is coarser
  // cost_and_gradient's last J and g (H empty): gradient_and_step_matrix takes them at the same q and
  // horizon (an optimiser's accepted trial point, then the start of the next run from it).
  // cost_and_gradient itself always solves.
  LastGaussNewton last_gradient_;
  std::unique_ptr<Objective> step_matrix_;  // this objective at step_matrix_step() (made on first use)
  double gauss_newton_solve(const VectorXd& q, VectorXd& gradient, MatrixXd& H, MisfitProfile* profile);
  // Whether output sensitivities are interpolated in output space (no acceleration sensors) and
  // fit the memory budget: the Gauss–Newton sweep then keeps them.
  bool keeps_sensitivities() const;
  // Yx = C X + C₁ V and Yv = C V + C₁ A of the first `cols` columns of a recorded point, column by
  // column (a column's outputs do not depend on how many columns are stepped together).
  void point_outputs(int cols, const double* x, const double* v, const double* a, MatrixXd& Yx, MatrixXd& Yv) const;
  // Whether a pass over [t0, state_end] steps its tangents on two threads: sweep_threads, the
  // machine, P >= 2, and the recorded outputs within sensitivity_block_bytes.
  bool splits_sweep(double state_end, int P) const;
  // The state and all P tangents stepped over [t0, state_end] (the tangents to tangent_end), every
  // recorded point's outputs (point_outputs; sensors × (1 + P), or only the state's column once
  // the tangents have stopped) handed to `at` in time order. On one thread, or (splits_sweep) the
  // tangents in two groups, each stepped with its own copy of the state on its own thread and
  // solver, the outputs recorded and handed over in order once both are done — the same numbers
  // either way. `visit_state` (if set) sees every point of the state as it is stepped.
  using OutputVisit = std::function<void(double t, int cols, const MatrixXd& Yx, const MatrixXd& Yv)>;
  void stream_outputs(const Setup& s, const SecondOrderSolver& solver, double state_end, double tangent_end,
                      const std::vector<Derivative>& d, const SecondOrderSolver::Sink& visit_state,
                      const OutputVisit& at, SolverSummary& sum) const;
};

}  // namespace scoleid::identify
