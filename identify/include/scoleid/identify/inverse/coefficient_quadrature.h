#pragma once
// Eq. 25's quadrature of the coefficient gradient (docs/theory.md §6.4), accumulated as pattern sums.
//
// For a coefficient c_j carried by the operator terms M_j, D_j, K_j the gradient is
//
//   ∂J/∂c_j = ∫ ( −ṗᵀ M_j u̇  (or pᵀ M_j ü with rate sensors)  +  pᵀ D_j u̇  +  pᵀ K_j u ) dt,
//
// a sum over the nonzeros (r, s) of each term of value · ∫ left_r right_s dt with (left, right) =
// (ṗ, u̇), (p, ü), (p, u̇) or (p, u). The integral ∫ left_r right_s dt depends on the pair (r, s) and
// the kind of term only, not on the coefficient, so it is summed once per quadrature point over
// the union of the kind's nonzero patterns, and contracted with the terms' values once at the end.
// The pattern is stored by diagonals s − r = d: those it fills well (the interior of a
// finite-element matrix, whatever the interleaving of its fields) are summed as whole vectors, the
// few pairs elsewhere (the couplings to a rigid body's degrees of freedom) as a list. A point then
// costs about n vector multiply-adds per well-filled diagonal per kind instead of one indexed
// multiply-add per nonzero of every term: the cost of a point no longer grows with the number of
// coefficients, and the diagonal sums vectorise. When every term of a kind is symmetric (to the
// rounding of its assembly) only the upper triangle is kept, each pair summed with its mirror
// against the mean of the two values: half the cells.
#include <vector>

#include <Eigen/Dense>

#include "scoleid/identify/fe/structural_model.h"

namespace scoleid::identify {

class CoefficientQuadrature {
 public:
  // The terms of `model` that carry a coefficient c_j with needed[j] (all when `needed` is empty);
  // `rates`: the mass term is pᵀ M_j ü (rate sensors) instead of −ṗᵀ M_j u̇ (by parts, p(T) = 0).
  // A caller that forms ∂J/∂q = (∂c/∂q)ᵀ ∂J/∂c needs the coefficients whose row of ∂c/∂q is not
  // zero (needed_coefficients): the others' share of ∂J/∂q is zero whatever their ∂J/∂c_j, which
  // is then left as it was.
  CoefficientQuadrature(const StructuralModel& model, bool rates, const std::vector<bool>& needed = {});
  static std::vector<bool> needed_coefficients(const Eigen::MatrixXd& dcdq);

  // Clears the sums (before a gradient).
  void reset();
  // Adds a quadrature point of weight wt: multiplier p and ṗ, state x, u̇ = v, ü = a (used with rates).
  void add(double wt, const Eigen::VectorXd& p, const Eigen::VectorXd& pd, const Eigen::VectorXd& x,
           const Eigen::VectorXd& v, const Eigen::VectorXd& a);
  // Whether add reads v (a damping term, or the mass term by parts) and ṗ (the mass term by parts):
  // a caller that needs them for nothing else may leave them unset.
  bool reads_velocity() const { return damping_.used || (mass_.used && !rates_); }
  bool reads_multiplier_rate() const { return mass_.used && !rates_; }
  // Adds the contraction of the sums with the terms' values to gc (indexed by coefficient).
  void contract(Eigen::VectorXd& gc) const;

 private:
  // One kind of term (mass, damping, stiffness): its band sums and its pairs outside the band.
  struct Kind {
    bool used = false;
    bool symmetric = false;        // pairs r ≤ s only, each summed with its mirror
    std::vector<int> offsets;      // the diagonals s − r = d summed as vectors
    Eigen::MatrixXd band;          // n × offsets: column c holds Σ wt left_r right_{r+offsets[c]}
    std::vector<int> row, col;     // pairs outside the band
    Eigen::VectorXd outside;       // Σ wt left_r right_s for each of them
    struct Entry {
      int coefficient;
      double value;  // signed: −value for the mass term by parts
      int band_col;  // ≥ 0: band(row, band_col); < 0: outside[−1 − band_col]
      int row;
    };
    std::vector<Entry> entries;
  };
  static void build(Kind& k, const std::vector<OperatorTerm>& terms, int n, double sign,
                    const std::vector<bool>& needed);
  void accumulate(Kind& k, double wt, const Eigen::VectorXd& left, const Eigen::VectorXd& right);

  bool rates_;
  Kind mass_, damping_, stiffness_;
  Eigen::VectorXd scaled_;  // wt · left at the current point
};

}  // namespace scoleid::identify
