#pragma once
// What the optimisers minimise (optimizers.h): a misfit J(q) ≥ 0 between a model and data, with
// its gradient and Gauss–Newton matrix, and optionally a horizon — the part of a time record the
// cost is taken over, for the horizon continuation (docs/theory.md §7.2).
//
// Implementations:
//   Objective       one time-domain experiment: state forward, costate backward (objective.h);
//   ModalMisfit     measured natural frequencies, damping ratios and mode shapes (modal_misfit.h);
//   JointMisfit     the sum of several of them, one parameter vector (joint_misfit.h).
// A misfit without a time record (modal data) has the horizon fixed at its end: data_start() = 0,
// data_end() = horizon() = 1, and set_horizon does nothing, so no continuation takes place.
#include <vector>

#include "scoleid/identify/fe/structural_model.h"

namespace scoleid::identify {

class Misfit {
public:
  virtual ~Misfit() = default;

  // Relative mean-square misfit on [t0, t_i] for each sample time t_i (objective.h).
  struct MisfitProfile {
    std::vector<double> t, misfit;
    // The longest t_i with misfit <= bound (−inf if none).
    double longest_within(double bound) const;
  };

  virtual int size() const = 0;
  virtual double horizon() const = 0;
  virtual double data_start() const = 0;
  // Where horizons are measured from (optimizers.h, horizon continuation): the data's start, or
  // for a record with a quiet start, where the inputs begin to act (Objective).
  virtual double response_start() const { return data_start(); }
  virtual double data_end() const = 0;
  virtual void set_horizon(double T) = 0;
  // Whether the data form a time record the horizon cuts (false for modal data).
  virtual bool has_horizon() const { return true; }
  // Number of data values on the horizon (the automatic cost-stall test, optimizers.h).
  virtual long data_points() const = 0;

  virtual double cost(const VectorXd& q) = 0;
  virtual double cost_and_gradient(const VectorXd& q, VectorXd& gradient) = 0;
  // cost_and_gradient, or its last evaluation where the objective keeps it for q and the horizon
  // (Objective: an optimiser's accepted trial, asked again where the next run starts from it).
  virtual double recalled_cost_and_gradient(const VectorXd& q, VectorXd& gradient) { return cost_and_gradient(q, gradient); }
  // J, g and the Gauss–Newton matrix H (with `profile`: the misfit profile over the whole record).
  virtual double gauss_newton(const VectorXd& q, VectorXd& gradient, MatrixXd& H, MisfitProfile* profile = nullptr) = 0;
  // J, g and a Gauss–Newton matrix for the optimiser's step alone (not for uncertainty): by default
  // gauss_newton's; a misfit may take it on a coarser discretisation than J and g, which moves the
  // steps but not the minimum they lead to.
  virtual double gradient_and_step_matrix(const VectorXd& q, VectorXd& gradient, MatrixXd& H) {
    return gauss_newton(q, gradient, H);
  }
  // Whether that matrix is an evaluation of its own (then cost_and_gradient gives J and g, and
  // step_matrix the matrix, at the cost of the two apart), and the matrix alone.
  virtual bool has_separate_step_matrix() const { return false; }
  virtual void step_matrix(const VectorXd& q, MatrixXd& H) {
    VectorXd g;
    gauss_newton(q, g, H);
  }
  virtual MisfitProfile misfit_profile(const VectorXd& q) = 0;
  // H v without forming H, where the misfit offers it.
  virtual VectorXd gauss_newton_product(const VectorXd& q, const VectorXd& v) = 0;
  virtual bool has_matrix_free_products() const = 0;
};

}  // namespace scoleid::identify
