#include "scoleid/identify/inverse/tied_parameterization.h"

#include <map>
#include <stdexcept>

namespace scoleid::identify {

TiedParameterization::TiedParameterization(const Parameterization& base, VectorXd q0, std::vector<int> group,
                                           std::vector<std::string> names)
    : base_(base), q0_(std::move(q0)), group_(std::move(group)), names_(std::move(names)) {
  if (static_cast<int>(group_.size()) != base_.size() || q0_.size() != base_.size())
    throw std::invalid_argument("TiedParameterization: one group and one reference value per base parameter");
  std::vector<int> count(names_.size(), 0);
  for (int g : group_) {
    if (g < 0 || g >= static_cast<int>(names_.size())) throw std::invalid_argument("TiedParameterization: group out of range");
    ++count[static_cast<std::size_t>(g)];
  }
  for (int c : count)
    if (c == 0) throw std::invalid_argument("TiedParameterization: empty group");
}

VectorXd TiedParameterization::expand(const VectorXd& theta) const {
  VectorXd q = q0_;
  for (Eigen::Index i = 0; i < q.size(); ++i) q[i] *= theta[group_[static_cast<std::size_t>(i)]];
  return q;
}

void TiedParameterization::coefficients(const VectorXd& theta, VectorXd& c, MatrixXd& dcdq) const {
  MatrixXd dcdq_base;
  base_.coefficients(expand(theta), c, dcdq_base);
  dcdq = MatrixXd::Zero(dcdq_base.rows(), static_cast<Eigen::Index>(names_.size()));
  for (Eigen::Index i = 0; i < q0_.size(); ++i) dcdq.col(group_[static_cast<std::size_t>(i)]) += q0_[i] * dcdq_base.col(i);
}

std::map<std::string, double> TiedParameterization::physical(const VectorXd& theta) const {
  return base_.physical(expand(theta));
}

std::vector<std::vector<int>> section_families(const std::vector<std::string>& names) {
  std::map<std::string, std::map<int, int>> fam;  // stem → index → position
  for (std::size_t i = 0; i < names.size(); ++i) {
    const auto& n = names[i];
    const auto u = n.rfind('_');
    if (u == std::string::npos || u + 1 >= n.size()) continue;
    const std::string digits = n.substr(u + 1);
    if (digits.find_first_not_of("0123456789") != std::string::npos || digits.size() > 6) continue;
    fam[n.substr(0, u)][std::stoi(digits)] = static_cast<int>(i);
  }
  std::vector<std::vector<int>> out;
  for (const auto& [stem, members] : fam) {
    const int N = static_cast<int>(members.size());
    if (N < 2 || members.begin()->first != 1 || members.rbegin()->first != N) continue;
    std::vector<int> f;
    for (const auto& [k, pos] : members) f.push_back(pos);
    out.push_back(f);
  }
  return out;
}

std::pair<std::vector<int>, std::vector<std::string>> block_grouping(const std::vector<std::string>& names,
                                                                     const std::vector<std::vector<int>>& families,
                                                                     int blocks) {
  std::vector<int> group(names.size(), -1);
  std::vector<std::string> gnames;
  for (const auto& f : families) {
    const int N = static_cast<int>(f.size());
    const int B = std::max(1, std::min(blocks, N));
    const std::string stem = names[static_cast<std::size_t>(f[0])].substr(0, names[static_cast<std::size_t>(f[0])].rfind('_'));
    const int first = static_cast<int>(gnames.size());
    for (int b = 0; b < B; ++b) {
      int lo = N, hi = -1;
      for (int j = 0; j < N; ++j)
        if (j * B / N == b) lo = std::min(lo, j), hi = std::max(hi, j);
      gnames.push_back(lo == hi ? names[static_cast<std::size_t>(f[static_cast<std::size_t>(lo)])]
                                : stem + "_" + std::to_string(lo + 1) + ":" + std::to_string(hi + 1));
    }
    for (int j = 0; j < N; ++j) group[static_cast<std::size_t>(f[static_cast<std::size_t>(j)])] = first + j * B / N;
  }
  for (std::size_t i = 0; i < names.size(); ++i)
    if (group[i] < 0) {
      group[i] = static_cast<int>(gnames.size());
      gnames.push_back(names[i]);
    }
  return {group, gnames};
}

}  // namespace scoleid::identify
