#include "scoleid/identify/fe/frame_model.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "scoleid/identify/fe/analytic_frame.h"
#include "scoleid/identify/fe/hermite_beam.h"
#include "scoleid/io/error.h"

namespace scoleid::identify {

namespace {
// A scenario that passed io::validate_scenario holds only what the model reads (io/frame_kind.cpp,
// check); anything else here is a caller's defect.
[[noreturn]] void unchecked(const std::string& what) {
  throw std::logic_error("build_frame: " + what + " is not one the frame model reads (io::validate_scenario refuses it)");
}
}  // namespace

using io::format_value;

Eigen::RowVectorXd FrameFE::row(double s, int derivative) const {
  Eigen::RowVectorXd r = Eigen::RowVectorXd::Zero(model.ndof);
  int k = 0;
  while (k + 1 < storeys && s > base[static_cast<std::size_t>(k + 1)]) ++k;
  const int ne = storey_elements[static_cast<std::size_t>(k)];
  const double h = (base[static_cast<std::size_t>(k + 1)] - base[static_cast<std::size_t>(k)]) / ne;
  const double x = std::clamp(s - base[static_cast<std::size_t>(k)], 0.0, ne * h);
  const int e = std::min(ne - 1, static_cast<int>(std::floor(x / h)));
  const double xi = (x - e * h) / h;
  const hermite::Vec4 n = derivative == 1 ? hermite::slope(xi, h) : hermite::shape(xi, h);
  const auto& nodes = dofs[static_cast<std::size_t>(k)][0];
  for (int a = 0; a < 4; ++a) {
    const int d = nodes[static_cast<std::size_t>(e + a / 2)][static_cast<std::size_t>(a % 2)];
    if (d >= 0) r[d] += n[a];
  }
  return r;
}

FrameFE build_frame(const io::FrameSpec& frame, int elements, const std::vector<io::InputSpec>& inputs,
                    const std::vector<io::SensorSpec>& sensors) {
  if (elements < 1) unchecked(std::to_string(elements) + " elements");
  FrameFE fe;
  fe.storeys = frame.storeys();
  fe.columns = frame.columns;
  fe.height = frame.height();
  fe.elements = 0;
  const int n = fe.storeys;
  if (static_cast<int>(frame.EI.size()) != n || static_cast<int>(frame.floor_mass.size()) != n)
    throw std::logic_error("build_frame: EI and floor_mass must hold one value per storey");
  fe.base.push_back(0.0);
  for (int k = 0; k < n; ++k) {
    fe.base.push_back(fe.base.back() + frame.heights[static_cast<std::size_t>(k)]);
    // The storey's share of the elements, at least one per column.
    const int ne = std::max(1, static_cast<int>(std::lround(elements * frame.heights[static_cast<std::size_t>(k)] / fe.height)));
    fe.storey_elements.push_back(ne);
    fe.elements += ne;
  }
  // DOFs: the floors' sways first, then each column's interior nodes (w, w_s).
  int ndof = n;
  fe.dofs.resize(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) {
    const int ne = fe.storey_elements[static_cast<std::size_t>(k)];
    auto& storey = fe.dofs[static_cast<std::size_t>(k)];
    storey.resize(static_cast<std::size_t>(fe.columns));
    for (auto& col : storey) {
      col.assign(static_cast<std::size_t>(ne + 1), {-1, -1});
      col.front()[0] = k == 0 ? -1 : fe.floor_dof(k - 1);
      col.back()[0] = fe.floor_dof(k);
      for (int j = 1; j < ne; ++j) col[static_cast<std::size_t>(j)] = {ndof, ndof + 1}, ndof += 2;
    }
  }
  StructuralModel& m = fe.model;
  m.ndof = ndof;
  m.ncoef = 1 + 4 * n;
  m.coefficient_names.push_back("rho_A");
  for (int k = 0; k < n; ++k) m.coefficient_names.push_back("EI_" + std::to_string(k + 1));
  for (int k = 0; k < n; ++k) m.coefficient_names.push_back("d_" + std::to_string(k + 1));
  for (int k = 0; k < n; ++k) m.coefficient_names.push_back("c_kv_" + std::to_string(k + 1));
  for (int k = 0; k < n; ++k) m.coefficient_names.push_back("floor_mass_" + std::to_string(k + 1));
  m.dof_group.assign(static_cast<std::size_t>(ndof), 0);
  for (int d = n + 1; d < ndof; d += 2) m.dof_group[static_cast<std::size_t>(d)] = 1;  // w_s

  using Trip = Eigen::Triplet<double>;
  auto to_sparse = [ndof](const std::vector<Trip>& t) {
    SparseMatrix A(ndof, ndof);
    A.setFromTriplets(t.begin(), t.end());
    A.makeCompressed();
    return A;
  };
  std::vector<Trip> mass;
  for (int k = 0; k < n; ++k) {
    const int ne = fe.storey_elements[static_cast<std::size_t>(k)];
    const double h = frame.heights[static_cast<std::size_t>(k)] / ne;
    const hermite::Mat4 Me = hermite::mass(h, 0.0, h), Ke = hermite::stiffness(h, 0.0, h), Ge = hermite::slope_product(h, 0.0, h);
    std::vector<Trip> stiff, slope;
    for (const auto& col : fe.dofs[static_cast<std::size_t>(k)])
      for (int e = 0; e < ne; ++e) {
        std::array<int, 4> d{};
        for (int a = 0; a < 4; ++a) d[static_cast<std::size_t>(a)] = col[static_cast<std::size_t>(e + a / 2)][static_cast<std::size_t>(a % 2)];
        for (int a = 0; a < 4; ++a)
          for (int b = 0; b < 4; ++b) {
            const int ra = d[static_cast<std::size_t>(a)], rb = d[static_cast<std::size_t>(b)];
            if (ra < 0 || rb < 0) continue;
            mass.emplace_back(ra, rb, Me(a, b));
            stiff.emplace_back(ra, rb, Ke(a, b));
            slope.emplace_back(ra, rb, Ge(a, b));
          }
      }
    const SparseMatrix Kk = to_sparse(stiff);
    m.stiffness.push_back({Kk, fe.coef_EI(k)});
    m.damping.push_back({to_sparse(slope), fe.coef_chen_russell(k)});
    m.damping.push_back({Kk, fe.coef_kelvin_voigt(k)});
  }
  m.mass.push_back({to_sparse(mass), fe.coef_rho_A()});
  for (int k = 0; k < n; ++k) m.mass.push_back({to_sparse({Trip(fe.floor_dof(k), fe.floor_dof(k), 1.0)}), fe.coef_floor_mass(k)});

  for (std::size_t i = 0; i < inputs.size(); ++i) {
    const auto& in = inputs[i];
    const std::string f = "inputs[" + std::to_string(i) + "]";
    if (in.at != io::Site::Frame || !(in.location >= 0.0 && in.location <= fe.height * (1.0 + 1e-12))) unchecked(f);
    ModelInput mi;
    mi.name = in.name;
    mi.vector = fe.row(in.location, in.kind == io::InputKind::Moment ? 1 : 0).transpose();
    m.inputs.push_back(std::move(mi));
  }
  for (std::size_t i = 0; i < sensors.size(); ++i) {
    const auto& se = sensors[i];
    const std::string f = "sensors[" + std::to_string(i) + "]";
    if (se.at != io::Site::Frame || !io::reads(io::Structure::Frame, se.kind) ||
        !(se.location >= 0.0 && se.location <= fe.height * (1.0 + 1e-12)))
      unchecked(f);
    ModelSensor ms;
    ms.name = se.name;
    ms.kind = se.kind;
    ms.order = io::derivative_order(se.kind);
    ms.row = fe.row(se.location, se.kind == io::SensorKind::Rotation ? 1 : 0);
    m.sensors.push_back(std::move(ms));
  }
  return fe;
}

VectorXd frame_coefficients(const FrameFE& fe, const io::FrameSpec& frame) {
  VectorXd c(fe.model.ncoef);
  c[fe.coef_rho_A()] = frame.rho_A;
  for (int k = 0; k < fe.storeys; ++k) {
    const double ei = frame.EI[static_cast<std::size_t>(k)];
    c[fe.coef_EI(k)] = ei;
    c[fe.coef_chen_russell(k)] = 2.0 * frame.zeta * std::sqrt(frame.rho_A * ei);
    c[fe.coef_kelvin_voigt(k)] = frame.tau * ei;
    c[fe.coef_floor_mass(k)] = frame.floor_mass[static_cast<std::size_t>(k)];
  }
  return c;
}

ParameterSpace frame_parameter_space(const FrameFE& fe, const io::FrameSpec& frame) {
  const int n = fe.storeys;
  ParameterSpace sp;
  sp.structure = "frame";
  sp.quantities.push_back("rho_A");
  sp.value.push_back(frame.rho_A);
  sp.true_value.push_back(true);
  ParameterSpace::Group ei{"EI", {}, true};
  for (int k = 0; k < n; ++k) {
    sp.quantities.push_back("EI_" + std::to_string(k + 1));
    sp.value.push_back(frame.EI[static_cast<std::size_t>(k)]);
    sp.true_value.push_back(true);
    ei.members.push_back(1 + k);
  }
  sp.quantities.push_back("zeta");
  sp.value.push_back(frame.zeta);
  sp.true_value.push_back(true);
  sp.quantities.push_back("tau");
  sp.value.push_back(frame.tau);
  sp.true_value.push_back(true);
  for (int k = 0; k < n; ++k) {
    sp.quantities.push_back("floor_mass_" + std::to_string(k + 1));
    sp.value.push_back(frame.floor_mass[static_cast<std::size_t>(k)]);
    sp.true_value.push_back(true);
  }
  sp.groups.push_back(ei);
  sp.rho_A = 0;
  sp.paper_requirement = "needs a uniform beam (structure: beam), not a frame";
  sp.ncoef = fe.model.ncoef;
  // φ = [ρA, EI_1..EI_n, ζ, τ, m_1..m_n] → c = [ρA, EI_1..EI_n, d_1..d_n, c_1..c_n, m_1..m_n],
  // d_k = 2ζ√(ρA EI_k), c_k = τ EI_k.
  sp.coefficients = [n](const std::vector<ParameterSpace::Cd>& f) {
    std::vector<ParameterSpace::Cd> c(static_cast<std::size_t>(1 + 4 * n));
    c[0] = f[0];
    const auto zeta = f[static_cast<std::size_t>(n + 1)], tau = f[static_cast<std::size_t>(n + 2)];
    for (int k = 0; k < n; ++k) {
      const auto ei = f[static_cast<std::size_t>(1 + k)];
      c[static_cast<std::size_t>(1 + k)] = ei;
      c[static_cast<std::size_t>(1 + n + k)] = 2.0 * zeta * std::sqrt(f[0] * ei);
      c[static_cast<std::size_t>(1 + 2 * n + k)] = tau * ei;
      c[static_cast<std::size_t>(1 + 3 * n + k)] = f[static_cast<std::size_t>(n + 3 + k)];
    }
    return c;
  };
  return sp;
}

namespace {

class FrameStructure final : public FEStructure {
public:
  FrameStructure(const io::Scenario& sc, int elements)
      : fe_(build_frame(sc.frame, elements, sc.inputs, sc.sensors)) {}
  const StructuralModel& model() const override { return fe_.model; }
  int elements() const override { return fe_.elements; }
  double length() const override { return fe_.height; }
  ParameterSpace parameter_space(const io::Scenario& sc) const override { return frame_parameter_space(fe_, sc.frame); }
  VectorXd coefficients(const io::Scenario& sc) const override { return frame_coefficients(fe_, sc.frame); }
  std::vector<double> exact_hz(const io::Scenario& sc, int count, std::string& what) const override {
    what = "the columns' exact dynamic stiffness on the floors' sways (undamped, below the first column mode)";
    std::vector<double> hz;
    for (double w : analytic::frame_omegas(sc.frame, count)) hz.push_back(w / (2.0 * M_PI));
    return hz;
  }

private:
  FrameFE fe_;
};

}  // namespace

std::unique_ptr<FEStructure> make_frame_structure(const io::Scenario& sc, int elements) {
  return std::make_unique<FrameStructure>(sc, elements);
}

}  // namespace scoleid::identify
