// The mast's foreshortening: the slopes' rows and the quadratic forms of its axial shift
// (scole_nonlinear.h).
#include "parts.h"

namespace scoleid::identify {

using Eigen::Matrix3d;
using Eigen::Vector3d;

ScoleNonlinear::Foreshortening::Slopes ScoleNonlinear::Foreshortening::slopes(const VectorXd& x) const {
  Slopes S(2, static_cast<Eigen::Index>(node.size()));
  for (std::size_t j = 0; j < node.size(); ++j) {
    const Node& nd = node[j];
    Eigen::Vector2d a = Eigen::Vector2d::Zero();
    for (std::size_t k = 0; k < nd.cols.size(); ++k) a += nd.rows.col(static_cast<Eigen::Index>(k)) * x[nd.cols[k]];
    S.col(static_cast<Eigen::Index>(j)) = a;
  }
  return S;
}

void ScoleNonlinear::Foreshortening::add(std::size_t j, const Eigen::Vector2d& a, VectorXd& out) const {
  const Node& nd = node[j];
  for (std::size_t k = 0; k < nd.cols.size(); ++k) out[nd.cols[k]] += nd.rows.col(static_cast<Eigen::Index>(k)).dot(a);
}

void ScoleNonlinear::Foreshortening::forms(const Slopes& X, const Slopes& Y, std::vector<double>& out) const {
  auto form = [&](std::size_t j) {
    const auto jj = static_cast<Eigen::Index>(j);
    return node[j].weight * X.col(jj).dot(Y.col(jj));
  };
  out.assign(size(), 0.0);
  double below = 0.0;  // over the elements below the current one
  int el = 0;
  const std::size_t first_partial = 3 * static_cast<std::size_t>(elements);
  for (std::size_t i = 0; i < size(); ++i) {
    for (; el < element_of[i]; ++el)
      for (std::size_t q = 0; q < 3; ++q) below += form(3 * static_cast<std::size_t>(el) + q);
    double v = below;
    for (std::size_t q = 0; q < 3; ++q) v += form(first_partial + 3 * i + q);
    out[i] = v;
  }
}

template <class G, class Visit>
void ScoleNonlinear::Foreshortening::coefficients(const std::vector<G>& gamma, G zero, Visit&& visit) const {
  const std::size_t first_partial = 3 * static_cast<std::size_t>(elements);
  G above = zero;
  std::size_t i = size();
  for (int el = elements - 1; el >= 0; --el) {
    for (std::size_t q = 0; q < 3; ++q) visit(3 * static_cast<std::size_t>(el) + q, above);
    for (; i > 0 && element_of[i - 1] == el; --i) {
      for (std::size_t q = 0; q < 3; ++q) visit(first_partial + 3 * (i - 1) + q, gamma[i - 1]);
      above += gamma[i - 1];
    }
  }
}

void ScoleNonlinear::Foreshortening::apply(const std::vector<double>& gamma, const Slopes& X, VectorXd& out) const {
  coefficients(gamma, 0.0, [&](std::size_t j, double c) {
    if (c != 0.0) add(j, Eigen::Vector2d(c * node[j].weight * X.col(static_cast<Eigen::Index>(j))), out);
  });
}

void ScoleNonlinear::Foreshortening::apply_rows(const std::vector<Eigen::Matrix<double, 6, 1>>& gamma, const Slopes& X,
                                                MatrixXd& out) const {
  using Vector6 = Eigen::Matrix<double, 6, 1>;
  coefficients(gamma, Vector6::Zero().eval(), [&](std::size_t j, const Vector6& g) {
    const Node& nd = node[j];
    const Eigen::Vector2d a = nd.weight * X.col(static_cast<Eigen::Index>(j));
    for (std::size_t k = 0; k < nd.cols.size(); ++k) out.col(nd.cols[k]) += g * nd.rows.col(static_cast<Eigen::Index>(k)).dot(a);
  });
}

}  // namespace scoleid::identify
