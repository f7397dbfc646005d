#include "scoleid/identify/fe/state_space.h"

#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/Eigenvalues>

namespace scoleid::identify {
namespace {

struct Dense {
  MatrixXd M, D, K, B0;
};

Dense dense(const StructuralModel& model, const VectorXd& c) {
  const AssembledModel a = assemble(model, c);
  Dense d{MatrixXd(a.M), MatrixXd(a.D), MatrixXd(a.K), MatrixXd::Zero(model.ndof, static_cast<Eigen::Index>(a.loads.size()))};
  for (std::size_t i = 0; i < a.loads.size(); ++i) d.B0.col(static_cast<Eigen::Index>(i)) = a.loads[i];
  return d;
}

std::vector<std::string> input_names(const StructuralModel& model) {
  std::vector<std::string> n;
  for (const auto& in : model.inputs) n.push_back(in.name);
  return n;
}

std::vector<std::string> output_names(const StructuralModel& model) {
  std::vector<std::string> n;
  for (const auto& s : model.sensors) n.push_back(s.name);
  return n;
}

}  // namespace

StateSpace state_space(const StructuralModel& model, const VectorXd& c) {
  const Dense d = dense(model, c);
  const Eigen::Index n = model.ndof, m = d.B0.cols(), p = static_cast<Eigen::Index>(model.sensors.size());
  const Eigen::LDLT<MatrixXd> mass(d.M);
  if (mass.info() != Eigen::Success || !mass.isPositive())
    throw std::runtime_error("state space: the mass matrix is not positive definite at these parameters");
  const MatrixXd MinvK = mass.solve(d.K), MinvD = mass.solve(d.D), MinvB = mass.solve(d.B0);
  StateSpace s;
  s.A = MatrixXd::Zero(2 * n, 2 * n);
  s.A.topRightCorner(n, n).setIdentity();
  s.A.bottomLeftCorner(n, n) = -MinvK;
  s.A.bottomRightCorner(n, n) = -MinvD;
  s.B = MatrixXd::Zero(2 * n, m);
  s.B.bottomRows(n) = MinvB;
  const MatrixXd C0 = model.output_matrix(0), C1 = model.output_matrix(1), C2 = model.output_matrix(2);
  s.C.resize(p, 2 * n);
  s.C.leftCols(n) = C0 - C2 * MinvK;
  s.C.rightCols(n) = C1 - C2 * MinvD;
  s.D = C2 * MinvB;
  s.inputs = input_names(model);
  s.outputs = output_names(model);
  for (const auto& sensor : model.sensors) s.output_order.push_back(sensor.order);
  return s;
}

ModalModel modal_model(const StructuralModel& model, const VectorXd& c) {
  const Dense d = dense(model, c);
  const Eigen::GeneralizedSelfAdjointEigenSolver<MatrixXd> eig(d.K, d.M);  // φᵀ M φ = 1, ascending
  const VectorXd lambda = eig.eigenvalues();
  const MatrixXd& phi = eig.eigenvectors();
  const Eigen::Index modes = lambda.size();
  ModalModel mm;
  mm.omega.resize(modes);
  mm.zeta.resize(modes);
  const double top = std::sqrt(std::max(lambda.maxCoeff(), 0.0));
  for (Eigen::Index k = 0; k < modes; ++k) {
    mm.omega[k] = std::sqrt(std::max(lambda[k], 0.0));
    const double modal_damping = phi.col(k).dot(d.D * phi.col(k));
    mm.zeta[k] = mm.omega[k] > 1e-6 * top ? modal_damping / (2.0 * mm.omega[k]) : std::numeric_limits<double>::quiet_NaN();
  }
  mm.output_shapes.resize(static_cast<Eigen::Index>(model.sensors.size()), modes);
  for (std::size_t j = 0; j < model.sensors.size(); ++j) mm.output_shapes.row(static_cast<Eigen::Index>(j)) = model.sensors[j].row * phi;
  mm.input_shapes = d.B0.transpose() * phi;
  mm.mass_shapes = d.M * phi;
  mm.inputs = input_names(model);
  mm.outputs = output_names(model);
  return mm;
}

}  // namespace scoleid::identify
