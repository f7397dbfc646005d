#include "scoleid/identify/fe/structural_model.h"

namespace scoleid::identify {

SparseMatrix StructuralModel::assemble(const std::vector<OperatorTerm>& terms, const VectorXd& c) const {
  SparseMatrix A(ndof, ndof);
  for (const auto& t : terms) {
    const double w = t.coefficient < 0 ? 1.0 : c[t.coefficient];
    if (w != 0.0) A += w * t.matrix;
  }
  A.makeCompressed();
  return A;
}

MatrixXd StructuralModel::output_matrix(int order) const {
  MatrixXd C = MatrixXd::Zero(static_cast<int>(sensors.size()), ndof);
  for (std::size_t k = 0; k < sensors.size(); ++k)
    if (sensors[k].order == order) C.row(static_cast<int>(k)) = sensors[k].row;
  return C;
}

bool StructuralModel::has_rate_outputs() const {
  for (const auto& s : sensors)
    if (s.order > 0) return true;
  return false;
}

AssembledModel assemble(const StructuralModel& model, const VectorXd& c) {
  AssembledModel a;
  a.M = model.assemble(model.mass, c);
  a.D = model.assemble(model.damping, c);
  a.K = model.assemble(model.stiffness, c);
  for (int i = 0; i < static_cast<int>(model.inputs.size()); ++i)
    a.loads.push_back(model.input_scale(i, c) * model.inputs[static_cast<std::size_t>(i)].vector);
  return a;
}

}  // namespace scoleid::identify
