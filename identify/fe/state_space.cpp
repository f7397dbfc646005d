#include "scoleid/identify/fe/state_space.h"

#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/Eigenvalues>

#include "scoleid/identify/fe/lowest_modes.h"
#include "scoleid/identify/fe/modal.h"

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

namespace {

// ζ from the modal damping, the shapes from the mass-normalised vectors; `rigid` says which are
// rigid-body modes (ζ NaN).
template <class Matrix, class Rigid>
ModalModel modal_model_from(const StructuralModel& model, const VectorXd& omega, const MatrixXd& phi, const Matrix& M,
                            const Matrix& D, const MatrixXd& B0, Rigid rigid) {
  const Eigen::Index modes = omega.size();
  ModalModel mm;
  mm.omega = omega;
  mm.zeta.resize(modes);
  for (Eigen::Index k = 0; k < modes; ++k) {
    const double modal_damping = phi.col(k).dot(VectorXd(D * phi.col(k)));
    mm.zeta[k] = !rigid(k) ? modal_damping / (2.0 * mm.omega[k]) : std::numeric_limits<double>::quiet_NaN();
  }
  mm.output_shapes.resize(static_cast<Eigen::Index>(model.sensors.size()), modes);
  for (std::size_t j = 0; j < model.sensors.size(); ++j) mm.output_shapes.row(static_cast<Eigen::Index>(j)) = model.sensors[j].row * phi;
  mm.input_shapes = B0.transpose() * phi;
  mm.mass_shapes = MatrixXd(M * phi);
  mm.inputs = input_names(model);
  mm.outputs = output_names(model);
  return mm;
}

// The few lowest modes of a large model (fe/lowest_modes.h), all matrices sparse.
ModalModel sparse_modal_model(const StructuralModel& model, const VectorXd& c, int elastic) {
  const AssembledModel a = assemble(model, c);
  LowestModesOptions o;
  o.flexible = elastic;
  const NaturalModes nm = lowest_modes(a.M, a.K, o);
  MatrixXd B0 = MatrixXd::Zero(model.ndof, static_cast<Eigen::Index>(a.loads.size()));
  for (std::size_t i = 0; i < a.loads.size(); ++i) B0.col(static_cast<Eigen::Index>(i)) = a.loads[i];
  return modal_model_from(model, nm.omega, nm.vectors, a.M, a.D, B0, [&](Eigen::Index k) { return !(nm.omega[k] >= nm.floor); });
}

}  // namespace

ModalModel modal_model(const StructuralModel& model, const VectorXd& c, int elastic) {
  // Six rigid-body modes at most in space: the sparse solver pays when these and the elastic ones are few.
  if (elastic > 0 && sparse_modes_pay(model.ndof, elastic + 6)) {
    try {
      return sparse_modal_model(model, c, elastic);
    } catch (const LowestModesFailure&) {
      // the dense solution below
    }
  }
  const Dense d = dense(model, c);
  const Eigen::GeneralizedSelfAdjointEigenSolver<MatrixXd> eig(d.K, d.M);  // φᵀ M φ = 1, ascending
  const VectorXd lambda = eig.eigenvalues();
  VectorXd omega(lambda.size());
  for (Eigen::Index k = 0; k < lambda.size(); ++k) omega[k] = std::sqrt(std::max(lambda[k], 0.0));
  const AssembledModel a = assemble(model, c);
  const double floor = rigid_floor(a.M, a.K);
  return modal_model_from(model, omega, eig.eigenvectors(), d.M, d.D, d.B0, [&](Eigen::Index k) { return !(omega[k] >= floor); });
}

}  // namespace scoleid::identify
