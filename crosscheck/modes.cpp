#include "scoleid/crosscheck/modes.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "scoleid/crosscheck/richardson.h"
#include "scoleid/identify/fe/modal.h"
#include "scoleid/identify/fe/structure.h"
#include "scoleid/io/error.h"
#include "scoleid/io/limits.h"
#include "scoleid/model/linearisation.h"
#include "scoleid/model/sensors.h"
#include "scoleid/model/truth_run.h"

namespace scoleid::crosscheck {

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kTwoPi = 6.283185307179586;

// The truth's structure with the shape stations as its only sensors; `scale` per row.
io::Scenario shape_scenario(const io::Scenario& truth_sc, int count, std::vector<double>& scale) {
  io::Scenario sc = truth_sc;
  sc.sensors.clear();
  scale.clear();
  for (const auto& s : io::shape_sensors(truth_sc, count)) {
    sc.sensors.push_back(s.spec);
    scale.push_back(s.scale);
  }
  return sc;
}

// Unit 2-norm, largest entry positive.
void normalise(Eigen::VectorXd& y) {
  const double n = y.norm();
  if (!(n > 0)) return;
  Eigen::Index i = 0;
  y.cwiseAbs().maxCoeff(&i);
  y *= (y[i] < 0 ? -1.0 : 1.0) / n;
}

struct SideModes {
  std::vector<double> hz;
  Eigen::MatrixXd shapes;
  std::vector<double> zeta;  // modal damping ratio per mode (when asked for), NaN if none matched
};

// The damping ratio of the damped mode nearest in frequency to each undamped one (light damping:
// |λ| is the undamped frequency to O(ζ²)); NaN where none lies within 1 % of it.
std::vector<double> match_damping(const std::vector<double>& hz, const std::vector<double>& damped_hz,
                                  const std::vector<double>& damped_zeta) {
  std::vector<double> z(hz.size(), std::numeric_limits<double>::quiet_NaN());
  for (std::size_t i = 0; i < hz.size(); ++i) {
    double best = 0.01;
    for (std::size_t k = 0; k < damped_hz.size(); ++k) {
      const double d = std::abs(damped_hz[k] / hz[i] - 1.0);
      if (d < best) {
        best = d;
        z[i] = damped_zeta[k];
      }
    }
  }
  return z;
}

SideModes chain_modes(const io::Scenario& shape_sc, const std::vector<double>& scale, int segments, int count,
                      bool damping) {
  auto structure = model::prepare_structure(shape_sc, segments);
  const auto sensors = model::resolve_sensors(shape_sc, *structure);
  const auto& matter = structure->matter();
  const auto& system = structure->system();
  SimTK::State state = system.getDefaultState();
  system.realize(state, SimTK::Stage::Velocity);
  model::OutputFunction outputs = [&](const SimTK::State& s) {
    system.realize(s, SimTK::Stage::Velocity);
    Eigen::VectorXd y(static_cast<Eigen::Index>(sensors.size()));
    for (std::size_t k = 0; k < sensors.size(); ++k)
      y[static_cast<Eigen::Index>(k)] = scale[k] * model::read_sensor(matter, s, sensors[k]);
    return y;
  };
  const model::ModeShapes ms = model::undamped_modes(system, state, outputs);
  SideModes out;
  const int k = std::min<int>(count, static_cast<int>(ms.omega.size()));
  for (int i = 0; i < k; ++i) out.hz.push_back(ms.omega[i] / kTwoPi);
  out.shapes = ms.shapes.leftCols(k);
  if (damping) {
    // The damped modes from the full state Jacobian (dampers included), matched by frequency.
    std::vector<double> dhz, dz;
    for (const auto& m : model::natural_modes(system, state)) {
      dhz.push_back(m.omega / kTwoPi);
      dz.push_back(m.damping_ratio);
    }
    out.zeta = match_damping(out.hz, dhz, dz);
  }
  return out;
}

SideModes fe_modes(const io::Scenario& shape_sc, const std::vector<double>& scale, int elements, int count,
                   bool damping) {
  const auto fe = identify::make_structure(shape_sc, elements);
  const auto& model = fe->model();
  const identify::AssembledModel ops = identify::assemble(model, fe->coefficients(shape_sc));
  const identify::NaturalModes nm = identify::natural_modes(ops.M, ops.K);
  Eigen::MatrixXd C = model.output_matrix(0);
  for (std::size_t r = 0; r < scale.size(); ++r) C.row(static_cast<Eigen::Index>(r)) *= scale[r];
  SideModes out;
  std::vector<Eigen::VectorXd> cols;
  for (int i = 0; i < nm.omega.size() && static_cast<int>(out.hz.size()) < count; ++i) {
    if (!(nm.omega[i] > nm.floor) || !std::isfinite(nm.omega[i])) continue;
    out.hz.push_back(nm.omega[i] / kTwoPi);
    Eigen::VectorXd y = C * nm.vectors.col(i);
    normalise(y);
    cols.push_back(y);
  }
  out.shapes.resize(C.rows(), static_cast<Eigen::Index>(cols.size()));
  for (std::size_t j = 0; j < cols.size(); ++j) out.shapes.col(static_cast<Eigen::Index>(j)) = cols[j];
  if (damping) {
    std::vector<double> dhz, dz;
    for (const auto& m : identify::damped_modes(Eigen::MatrixXd(ops.M), Eigen::MatrixXd(ops.D), Eigen::MatrixXd(ops.K))) {
      dhz.push_back(m.omega / kTwoPi);
      dz.push_back(m.zeta);
    }
    out.zeta = match_damping(out.hz, dhz, dz);
  }
  return out;
}

}  // namespace

bool ModesOptions::IsValid(std::string* why) const {
  auto fail = [&](const std::string& m) { if (why) *why = m; return false; };
  if (segments < 0 || segments == 1 || segments > io::limits::kMaxSegments) return fail("segments must be in [2, " + std::to_string(io::limits::kMaxSegments) + "] (0 = the scenario's)");
  if (elements < 0 || elements > io::limits::kMaxElements) return fail("elements must be in [1, " + std::to_string(io::limits::kMaxElements) + "] (0 = the scenario's)");
  if (count < 1 || count > 50) return fail("count must be in [1, 50]");
  if (levels < 1 || levels > 4) return fail("levels must be in [1, 4]");
  return true;
}

Eigen::MatrixXd mac_matrix(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B) {
  Eigen::MatrixXd mac(A.cols(), B.cols());
  for (int i = 0; i < A.cols(); ++i)
    for (int j = 0; j < B.cols(); ++j) {
      const double d = A.col(i).dot(B.col(j));
      const double n = A.col(i).squaredNorm() * B.col(j).squaredNorm();
      mac(i, j) = n > 0 ? d * d / n : 0.0;
    }
  return mac;
}

ModesReport compare_modes(const io::Scenario& scenario, const ModesOptions& opt) {
  std::string why;
  if (!opt.IsValid(&why)) throw io::InputError("modes: " + why);
  const auto t0 = std::chrono::steady_clock::now();
  const io::Scenario truth_sc = io::truth_scenario(scenario);
  std::vector<double> scale;
  const io::Scenario shape_sc = shape_scenario(truth_sc, opt.count, scale);
  const int n0 = opt.segments > 0 ? opt.segments : scenario.truth.segments;
  const int N0 = opt.elements > 0 ? opt.elements : scenario.identification.elements;
  const int nmax = n0 << (opt.levels - 1), Nmax = N0 << (opt.levels - 1);
  if (nmax > io::limits::kMaxSegments)
    throw io::InputError("modes: " + std::to_string(opt.levels) + " levels from " + std::to_string(n0) +
                         " segments reach " + std::to_string(nmax) + " > " +
                         std::to_string(io::limits::kMaxSegments));
  if (Nmax > io::limits::kMaxElements)
    throw io::InputError("modes: " + std::to_string(opt.levels) + " levels from " + std::to_string(N0) +
                         " elements reach " + std::to_string(Nmax) + " > " +
                         std::to_string(io::limits::kMaxElements));

  ModesReport rep;
  rep.scenario = scenario.name;
  rep.structure = io::to_string(scenario.structure);
  rep.truth_overrides = io::has_truth_overrides(scenario);
  for (const auto& s : shape_sc.sensors) rep.stations.push_back(s.name);
  std::vector<SideModes> chain, fe;
  for (int l = 0; l < opt.levels; ++l) {
    rep.segments.push_back(n0 << l);
    rep.elements.push_back(N0 << l);
    // Damping ratios on the coarsest level of each side (the one the MAC compares).
    chain.push_back(chain_modes(shape_sc, scale, rep.segments.back(), opt.count, l == 0));
    fe.push_back(fe_modes(shape_sc, scale, rep.elements.back(), opt.count, l == 0));
  }
  std::size_t count = static_cast<std::size_t>(opt.count);
  for (const auto& c : chain) count = std::min(count, c.hz.size());
  for (const auto& f : fe) count = std::min(count, f.hz.size());
  const std::vector<double> exact = identify::make_structure(shape_sc, N0)->exact_hz(truth_sc, static_cast<int>(count), rep.analytic);
  rep.mac = mac_matrix(chain.front().shapes.leftCols(static_cast<Eigen::Index>(count)),
                       fe.front().shapes.leftCols(static_cast<Eigen::Index>(count)));
  for (std::size_t i = 0; i < count; ++i) {
    ModeComparison m;
    m.index = static_cast<int>(i) + 1;
    for (const auto& c : chain) m.chain_hz.push_back(c.hz[i]);
    for (const auto& f : fe) m.fe_hz.push_back(f.hz[i]);
    const auto L = m.chain_hz.size();
    if (L >= 3) {
      // Differences below 1e-12 relative are round-off, not convergence.
      m.chain_rate = observed_order(m.chain_hz[L - 3], m.chain_hz[L - 2], m.chain_hz[L - 1], 2.0, 1e-12 * m.chain_hz[L - 1]);
      m.fe_rate = observed_order(m.fe_hz[L - 3], m.fe_hz[L - 2], m.fe_hz[L - 1], 2.0, 1e-12 * m.fe_hz[L - 1]);
    }
    m.chain_extrapolated = L >= 2 ? richardson(m.chain_hz[L - 2], m.chain_hz[L - 1], 2.0, 2.0) : m.chain_hz.back();
    if (i < exact.size()) m.analytic_hz = exact[i];
    const auto ii = static_cast<Eigen::Index>(i);
    m.mac = rep.mac(ii, ii);
    Eigen::Index best = 0;
    rep.mac.row(ii).maxCoeff(&best);
    m.best_fe = static_cast<int>(best) + 1;
    m.chain_zeta = chain.front().zeta[i];
    m.fe_zeta = fe.front().zeta[i];
    rep.modes.push_back(m);
  }
  rep.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return rep;
}

Table modes_table(const ModesReport& r) {
  Table t;
  t.title = "Natural frequencies [Hz], " + r.scenario + ": Simbody chain (n segments) against FE (N elements)";
  t.header.push_back("mode");
  for (int n : r.segments) t.header.push_back("chain n=" + std::to_string(n));
  t.header.push_back("chain extrap.");
  t.header.push_back("rate n");
  for (int N : r.elements) t.header.push_back("FE N=" + std::to_string(N));
  t.header.push_back("rate N");
  t.header.push_back("analytic");
  t.header.push_back("chain/FE-1 % (n, N)");
  t.header.push_back("extrap./FE-1 %");
  t.header.push_back("MAC");
  t.header.push_back("zeta chain (n)");
  t.header.push_back("zeta FE (N)");
  for (const auto& m : r.modes) {
    std::vector<std::string> row{std::to_string(m.index)};
    for (double f : m.chain_hz) row.push_back(number(f, 7));
    row.push_back(number(m.chain_extrapolated, 7));
    row.push_back(number(m.chain_rate, 3));
    for (double f : m.fe_hz) row.push_back(number(f, 7));
    row.push_back(number(m.fe_rate, 3));
    row.push_back(std::isnan(m.analytic_hz) ? "-" : number(m.analytic_hz, 7));
    row.push_back(percent(m.raw_difference(), 3));
    row.push_back(percent(m.extrapolated_difference(), 3));
    row.push_back(number(m.mac, 4) + (m.best_fe != m.index ? " (best FE " + std::to_string(m.best_fe) + ")" : ""));
    row.push_back(std::isnan(m.chain_zeta) ? "-" : number(m.chain_zeta, 5));
    row.push_back(std::isnan(m.fe_zeta) ? "-" : number(m.fe_zeta, 5));
    t.rows.push_back(row);
  }
  return t;
}

Table mac_table(const ModesReport& r) {
  Table t;
  t.title = "MAC: chain modes (rows, n=" + std::to_string(r.segments.front()) + ") against FE modes (columns, N=" +
            std::to_string(r.elements.front()) + ")";
  t.header.push_back("chain");
  for (int j = 0; j < r.mac.cols(); ++j) t.header.push_back("FE " + std::to_string(j + 1));
  for (int i = 0; i < r.mac.rows(); ++i) {
    std::vector<std::string> row{std::to_string(i + 1)};
    for (int j = 0; j < r.mac.cols(); ++j) row.push_back(number(r.mac(i, j), 3));
    t.rows.push_back(row);
  }
  return t;
}

nlohmann::json to_json(const ModesReport& r) {
  const auto num = json_number;
  nlohmann::json j;
  j["scenario"] = r.scenario;
  j["structure"] = r.structure;
  j["truth_overrides"] = r.truth_overrides;
  j["segments"] = r.segments;
  j["elements"] = r.elements;
  j["analytic"] = r.analytic.empty() ? nlohmann::json(nullptr) : nlohmann::json(r.analytic);
  j["shape_stations"] = r.stations;
  j["seconds"] = r.seconds;
  j["modes"] = nlohmann::json::array();
  for (const auto& m : r.modes) {
    nlohmann::json e;
    e["index"] = m.index;
    e["chain_hz"] = m.chain_hz;
    e["fe_hz"] = m.fe_hz;
    e["chain_rate"] = num(m.chain_rate);
    e["fe_rate"] = num(m.fe_rate);
    e["chain_extrapolated_hz"] = num(m.chain_extrapolated);
    e["analytic_hz"] = num(m.analytic_hz);
    e["chain_vs_fe"] = num(m.raw_difference());
    e["extrapolated_vs_fe"] = num(m.extrapolated_difference());
    e["mac"] = num(m.mac);
    e["best_fe_mode"] = m.best_fe;
    e["chain_damping_ratio"] = num(m.chain_zeta);
    e["fe_damping_ratio"] = num(m.fe_zeta);
    j["modes"].push_back(e);
  }
  nlohmann::json mac = nlohmann::json::array();
  for (int i = 0; i < r.mac.rows(); ++i) {
    std::vector<double> row(static_cast<std::size_t>(r.mac.cols()));
    for (int k = 0; k < r.mac.cols(); ++k) row[static_cast<std::size_t>(k)] = r.mac(i, k);
    mac.push_back(row);
  }
  j["mac"] = mac;
  return j;
}

io::ModalData chain_modal_data(const io::Scenario& scenario, int segments, int count) {
  const io::Scenario truth_sc = io::truth_scenario(scenario);
  io::Scenario sc = truth_sc;
  sc.sensors.clear();
  for (const auto& s : truth_sc.sensors)
    if (io::sensor_traits(s.kind).mode_shape) sc.sensors.push_back(s);
  if (sc.sensors.empty())
    io::fail_field(scenario.source, "sensors", "needs a displacement, rotation or line-of-sight sensor for mode shapes", "none");
  if (2 * segments > io::limits::kMaxSegments)
    throw io::InputError("modal data: " + std::to_string(2 * segments) + " segments (the lumping estimate) > " +
                         std::to_string(io::limits::kMaxSegments));
  const std::vector<double> scale(sc.sensors.size(), 1.0);
  const SideModes a = chain_modes(sc, scale, segments, count, false);
  const SideModes b = chain_modes(sc, scale, 2 * segments, count, false);
  io::ModalData d;
  for (const auto& s : sc.sensors) d.stations.push_back(s.name);
  // Mode i at n is compared with the mode at 2n of largest MAC (not the same index: close pairs,
  // such as SCOLE's roll and pitch bending, can swap order between resolutions).
  const Eigen::MatrixXd mac = mac_matrix(a.shapes, b.shapes);
  const double largest = a.shapes.cwiseAbs().maxCoeff();
  const std::size_t n = a.hz.size();
  for (std::size_t i = 0; i < n; ++i) {
    Eigen::VectorXd ya = a.shapes.col(static_cast<Eigen::Index>(i));
    if (!(ya.norm() > 1e-8 * largest)) continue;  // not seen at any station: no shape to write
    Eigen::Index j = 0;
    mac.row(static_cast<Eigen::Index>(i)).maxCoeff(&j);
    Eigen::VectorXd yb = b.shapes.col(j);
    io::ModalData::Mode m;
    m.label = static_cast<int>(i) + 1;
    m.frequency_hz = a.hz[i];
    m.frequency_std_hz = std::max(4.0 / 3.0 * std::abs(a.hz[i] - b.hz[static_cast<std::size_t>(j)]), 1e-7 * a.hz[i]);
    normalise(ya);
    normalise(yb);
    if (ya.dot(yb) < 0) yb = -yb;
    m.shape.assign(ya.data(), ya.data() + ya.size());
    m.shape_std = std::max(4.0 / 3.0 * (ya - yb).norm() / std::sqrt(static_cast<double>(ya.size())), 1e-6);
    d.modes.push_back(m);
  }
  d.source = "Simbody chain of " + scenario.name + ", " + std::to_string(segments) + " segments";
  return d;
}

}  // namespace scoleid::crosscheck
