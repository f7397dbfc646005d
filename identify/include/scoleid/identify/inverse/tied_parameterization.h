#pragma once
// Parameters tied into groups, for coarse-to-fine identification of distributed parameters
// (docs/theory.md §7.6).
//
// Over a base parameterization q ∈ R^P and a reference point q⁰, G multipliers θ:
//     q_i = q⁰_i · θ_{g(i)},      ∂c/∂θ = ∂c/∂q · diag(q⁰) · E,   E_ig = [g(i) = g]
// θ = 1 is q⁰. Tying the sections of EI(x) into B contiguous blocks fits the B-block profile
// that keeps q⁰'s shape within each block; B = 1, 2, 4, … up to the sections is a continuation
// from the data's coarsest, best-determined content to the finest, each level started where the
// previous one ended.
#include <string>
#include <vector>

#include "scoleid/identify/inverse/parameterization.h"

namespace scoleid::identify {

class TiedParameterization final : public Parameterization {
public:
  // group[i] in [0, G) for every base parameter i; every group non-empty.
  TiedParameterization(const Parameterization& base, VectorXd q0, std::vector<int> group,
                       std::vector<std::string> names);
  const std::vector<std::string>& names() const override { return names_; }
  void coefficients(const VectorXd& theta, VectorXd& c, MatrixXd& dcdq) const override;
  std::map<std::string, double> physical(const VectorXd& theta) const override;
  VectorXd initial() const override { return VectorXd::Ones(static_cast<Eigen::Index>(names_.size())); }
  VectorXd truth() const override { return {}; }
  // The base parameters at θ.
  VectorXd expand(const VectorXd& theta) const;

private:
  const Parameterization& base_;
  VectorXd q0_;
  std::vector<int> group_;
  std::vector<std::string> names_;
};

// Sectional families of a parameterization: parameters named X_1 … X_N (N >= 2, every index
// present), as the indices of X_1 … X_N in order. Empty if there are none.
std::vector<std::vector<int>> section_families(const std::vector<std::string>& names);

// The grouping that ties every family's N sections into `blocks` contiguous blocks (section j of N
// into block ⌊j·blocks/N⌋) and leaves the other parameters free; names "X_1:4" for a block of
// sections 1–4. Returns the group index per base parameter and the group names.
std::pair<std::vector<int>, std::vector<std::string>> block_grouping(const std::vector<std::string>& names,
                                                                     const std::vector<std::vector<int>>& families,
                                                                     int blocks);

}  // namespace scoleid::identify
