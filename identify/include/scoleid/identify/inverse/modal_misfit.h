#pragma once
// The misfit between measured modes (io/modal_data.h: natural frequencies, damping ratios, mode
// shapes at named sensors) and the undamped modes of the FE model (docs/theory.md §6.6).
//
// Model at q: c(q), ∂c/∂q from the parameterization; M, D, K assembled at c; the dense generalized
// eigenproblem K φ = λ M φ (fe/modal.h, natural_modes) gives all n modes, M-orthonormal, λ = ω²;
// the flexible modes are those with ω above its floor. Per flexible mode
//   frequency   f = ω / 2π
//   damping     ζ = φᵀ D φ / (2ω)     (light-damping approximation: the first-order perturbation of
//                                     the undamped mode by D; exact when Φᵀ D Φ is diagonal, e.g.
//                                     proportional damping, otherwise in error at second order in D
//                                     — the exact damped modes are fe/modal.h damped_modes)
//   shape       ψ = C_s φ             (C_s: the rows of the station sensors, acting on u)
//
// Clusters. Modes whose eigenvalues differ by less than options.cluster_tolerance relative
// (|λ_k − λ_{k−1}| < tol λ_k, chained) form a cluster — a repeated eigenvalue such as SCOLE's
// roll/pitch bending pair when the structure is symmetric. Individual eigenvalues are not
// differentiable at a crossing and the eigenvectors of a repeated eigenvalue are an arbitrary basis
// of its eigenspace, so every member of a cluster Φ_c (m columns) stands for the cluster:
//   λ̄ = mean of the members' λ_k (they differ by less than the tolerance), f = √λ̄ / 2π,
//   ζ̄ = tr(Φ_cᵀ D Φ_c) / (2 m √λ̄),
//   shape, for a measured shape ψ_m: the best-fitting shape of the cluster's span,
//        ψ = C_s Φ_c a,  a = (C_s Φ_c)⁺ ψ_m,
//   the projection of ψ_m onto the span, which maximises the cosine with ψ_m; all three are
//   invariant to the basis the eigensolver returns. A single mode is a cluster of one (m = 1), for
//   which these are the plain φᵀDφ/2ω and ±C_s φ.
//
// Matching (recomputed at every evaluation, so the cost can jump where the assignment changes):
// the candidates are the first min(n_flex, n_measured + options.extra_candidates) flexible modes.
// With shapes, by the modal assurance criterion against the cluster's projected shape,
//   MAC = (ψ_mᵀψ)² / (|ψ_m|² |ψ|²)   (= |P ψ_m|²/|ψ_m|², P the projector onto range C_s Φ_c),
// assigned one-to-one as the assignment of least total cost Σ(1 − MAC) (the Hungarian method;
// 1e-6 × the relative frequency difference breaks ties); without shapes, of least total relative
// frequency difference Σ|f − f_m| / f_m. Each candidate — each member of a
// cluster — is assigned at most once (two measured modes can share a two-member cluster). A
// candidate whose station shape vanishes (its singular values below 1e-8 of the largest station
// amplitude of the candidates) cannot be matched by shape. A measured mode left without a model
// mode is an error (std::domain_error: the model is outside the data's domain).
//
// Residuals, per measured mode in file order (each divided by its stated standard deviation):
//   r_f = (f − f_m) / σ_f;   with damping  r_ζ = (ζ − ζ_m) / σ_ζ;
//   with shapes, per station k:  r_k = (s ψ̂_k − ψ̂_m,k) / σ_shape,   ψ̂ = ψ/|ψ|,  s = sign(ψ̂_mᵀψ̂)
//   (s = +1 for the projected shape; held fixed in the derivative).
// J = ½ Σ r², N = data_points() residuals; the Gauss–Newton matrix JᵀJ of these residuals is the
// Fisher information of the data under the stated, independent Gaussian errors.
//
// Derivatives (exact, from the eigen-sensitivities over all n modes of the dense problem, rigid
// ones included, which is exact for a complete basis). Along parameter p: K' = Σ_j K_j ∂c_j/∂q_p,
// likewise M', D';
//   dλ_k = φ_kᵀ (K' − λ_k M') φ_k,   dω = dλ/(2ω)
//   dφ_k = Σ_{j ∉ cluster(k)} φ_j φ_jᵀ (K' − λ_k M') φ_k / (λ_k − λ_j) − ½ Φ_c (Φ_cᵀ M' φ_k)   (Nelson /
//          Fox–Kapoor modal expansion; for a single mode the last term is −½ (φ_kᵀM'φ_k) φ_k)
//   dλ̄ = (1/m) Σ_k φ_kᵀ (K' − λ_k M') φ_k = tr(Φ_cᵀ (K' − λ̄ M') Φ_c)/m for a repeated eigenvalue:
//          the mean is differentiable at a crossing, the individual eigenvalues are not; the mean is
//          what the cluster's frequency is, and what is differentiated.
//   dζ̄ = [tr(Φ_cᵀ D' Φ_c) + 2 tr(Φ_cᵀ D dΦ_c)] / (2 m ω̄) − ζ̄ dω̄/ω̄
//          (exact: the in-cluster part of dΦ_c enters only through the symmetric −½ Φ_cᵀM'Φ_c, the
//          rotation within the span leaves the trace unchanged)
//   dψ = C_s dΦ_c a with a held fixed, dψ̂ = (I − ψ̂ψ̂ᵀ) dψ / |ψ|.
// Holding a fixed is exact for a single mode (a only scales ψ, which the normalisation removes) and,
// for a cluster, exact for the gradient by the envelope argument: a maximises the cosine with ψ_m,
// on which the cluster's shape residual ½|r|² = (1 − s cos)/σ² alone depends, so ∂/∂a vanishes and
// only the part of dΦ_c outside the cluster's span matters — the sum over the modes outside the
// cluster, with no division by the small in-cluster gap. The Jacobian of a cluster's individual
// shape components is then the Gauss–Newton approximation with a fixed. All of it costs one
// dense eigensolve and O(n² P) per matched mode per evaluation.
//
// Large models (options.sparse_from degrees of freedom or more, when the modes the matching needs —
// the candidates and one above them — are at most an eighth of them): those modes alone from the
// sparse solver (fe/lowest_modes.h), and the modal expansion above, which needs every mode, replaced
// by Nelson's method for each matched single mode k (φ M-orthonormal, λ = ω²):
//   dλ = φᵀ (K' − λ M') φ,
//   (K − λ M) v = −(K' − λ M' − dλ M) φ  with v_r = 0,  r the largest component of φ (the
//          singular system made regular by taking out row and column r: one sparse LU per mode and
//          evaluation, one solve per parameter direction),
//   dφ = v + c φ,  c = −φᵀ M v − ½ φᵀ M' φ   (the normalisation φᵀ M φ = 1 kept),
// which is the same derivative, exactly. Frequencies need no dφ. A matched cluster of repeated
// eigenvalues with shapes or damping, or a cluster the computed modes may cut, takes the dense
// solution of every mode instead (Nelson's method needs a distinct eigenvalue).
//
// No time record: the horizon is fixed at data_end() = 1 (misfit.h); the misfit profile is the one
// point {t: 1, misfit: 2J/N}.
#include <vector>

#include "scoleid/identify/fe/lowest_modes.h"
#include "scoleid/identify/fe/structural_model.h"
#include "scoleid/identify/inverse/misfit.h"
#include "scoleid/identify/inverse/parameterization.h"
#include "scoleid/io/modal_data.h"

namespace scoleid::identify {

struct ModalMisfitOptions {
  int extra_candidates = 6;         // model modes beyond the number measured that may be matched
  double cluster_tolerance = 1e-6;  // relative eigenvalue difference below which modes are one cluster
  int sparse_from = kSparseModesFrom;  // degrees of freedom from which the few modes needed may come from the sparse solver (above)
  // The sparse solver's relative residual per mode (lowest_modes' tolerance). The misfit's rounding
  // is what the optimiser's line search and a difference quotient see: the vectors' error, about
  // this, enters the shape residuals divided by their std.
  double sparse_tolerance = 1e-11;
};

struct ModalMisfitCounters {
  int evaluations = 0;         // eigensolves, dense or sparse
  int sparse_evaluations = 0;  // of which the few modes needed, from the sparse solver
};

class ModalMisfit final : public Misfit {
public:
  // One measured mode's model partner at q.
  struct Match {
    int measured = 0;      // index into data().modes
    int model = 0;         // index among the model's flexible modes (0 = the lowest), ascending ω
    int cluster_size = 1;  // members of its cluster (1: a single mode)
    double mac = 0.0;      // MAC against the (cluster-projected) model shape; NaN without shapes
    double frequency_hz = 0.0;
    double damping_ratio = 0.0;  // ζ (light damping, see above)
  };

  // Data the door took (identify::check_modal_data: io::validate_modal_data, every station a
  // sensor acting on u); damping data need a model with damping terms (every scenario's has).
  // std::logic_error otherwise: a caller that went around the door.
  ModalMisfit(const StructuralModel& model, const Parameterization& params, io::ModalData data,
              ModalMisfitOptions options = {});

  int size() const override { return params_.size(); }
  double horizon() const override { return 1.0; }
  double data_start() const override { return 0.0; }
  double data_end() const override { return 1.0; }
  void set_horizon(double) override {}
  bool has_horizon() const override { return false; }
  long data_points() const override {
    return static_cast<long>(rows_per_mode_) * static_cast<long>(data_.modes.size());
  }

  double cost(const VectorXd& q) override;
  double cost_and_gradient(const VectorXd& q, VectorXd& gradient) override;  // g = Jᵀ r
  double gauss_newton(const VectorXd& q, VectorXd& gradient, MatrixXd& H, MisfitProfile* profile = nullptr) override;
  MisfitProfile misfit_profile(const VectorXd& q) override;
  VectorXd gauss_newton_product(const VectorXd& q, const VectorXd& v) override;  // Jᵀ(J v)
  bool has_matrix_free_products() const override { return true; }

  // The weighted residuals r (N = data_points()) at q and J = ½|r|²; with `jacobian`, ∂r/∂q (N × P).
  double residuals(const VectorXd& q, VectorXd& r, MatrixXd* jacobian = nullptr);
  // JᵀJ: the Fisher information of the data (the residuals are already divided by the stated
  // standard deviations).
  MatrixXd fisher(const VectorXd& q);
  // The assignment of measured to model modes at q, in the order of data().modes.
  std::vector<Match> matches(const VectorXd& q);

  const io::ModalData& data() const { return data_; }
  const ModalMisfitCounters& counters() const { return counters_; }
  void reset_counters() { counters_ = {}; }

private:
  struct Evaluation {
    VectorXd q;
    double J = 0.0;
    VectorXd r;
    MatrixXd jacobian;  // empty unless computed
    bool has_jacobian = false;
    std::vector<Match> matches;
  };
  const Evaluation& evaluate(const VectorXd& q, bool derivatives);

  const StructuralModel& model_;
  const Parameterization& params_;
  io::ModalData data_;
  ModalMisfitOptions options_;
  MatrixXd Cs_;                           // station rows (stations × ndof)
  std::vector<VectorXd> measured_shape_;  // unit-normalised measured shapes
  int rows_per_mode_ = 1;                 // 1 + damping + stations
  Evaluation last_;
  bool have_last_ = false;
  ModalMisfitCounters counters_;
};

}  // namespace scoleid::identify
