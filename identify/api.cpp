#include "scoleid/identify.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <cstdio>

#include "scoleid/io/error.h"
#include "scoleid/io/output_paths.h"
#include "scoleid/io/mat_file.h"
#include "scoleid/io/validation.h"

namespace scoleid {

bool IdentifyOptions::IsValid(std::string* why) const {
  auto bad = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  if (max_iterations && *max_iterations < 0) return bad("max_iterations must be >= 0, got " + std::to_string(*max_iterations));
  return true;
}

Identification::Identification(std::shared_ptr<identify::Problem> problem, identify::RunResult result)
    : problem_(std::move(problem)), result_(std::move(result)) {}

std::string Identification::verdict() const {
  const auto& r = result_;
  char buf[1024];
  if (r.summary.converged() && !r.fit.explains_data) {
    std::snprintf(buf, sizeof buf, "stopped at a point that does not explain the data (%s); %zu attempt%s",
                  io::one_line(r.fit.message).c_str(), r.attempts.size(), r.attempts.size() > 1 ? "s" : "");
    return buf;
  }
  if (!r.summary.converged()) {
    std::snprintf(buf, sizeof buf, "did not converge (%s%s%s)", identify::to_string(r.summary.termination),
                  r.summary.message.empty() ? "" : ": ", io::one_line(r.summary.message).c_str());
    return buf;
  }
  if (r.determines_nothing()) {
    std::snprintf(buf, sizeof buf,
                  "the data determine none of the %zu estimated parameters (each is NOT IDENTIFIABLE; its row says why): "
                  "the estimate is not the data's",
                  r.ident.identifiable.size());
    return buf;
  }
  if (!r.converged()) {  // the discrepancy principle found no weight (docs/theory.md §7.8)
    std::snprintf(buf, sizeof buf,
                  "no smoothness weight fits the data within the noise band (discrepancy principle not met down to %g)",
                  r.smoothness_weight);
    return buf;
  }
  return "";
}

std::vector<std::string> Identification::warnings() const {
  std::vector<std::string> w = problem_->warnings;  // what the record says of its channels
  w.insert(w.end(), result_.start_check.warnings.begin(), result_.start_check.warnings.end());
  const auto& id = result_.ident.identifiable;
  if (!id.empty() && std::none_of(id.begin(), id.end(), [](bool b) { return b; }))
    w.push_back("none of the " + std::to_string(id.size()) +
                " estimated parameters is identifiable from these data (each row says why); the estimates are not "
                "determined by the data");
  return w;
}

namespace {

Eigen::VectorXd coefficients_at(const identify::Problem& p, const Eigen::VectorXd& q) {
  Eigen::VectorXd c;
  Eigen::MatrixXd dcdq;
  p.params->coefficients(q, c, dcdq);
  return c;
}

nlohmann::json matrix_json(const Eigen::MatrixXd& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (Eigen::Index i = 0; i < m.rows(); ++i) {
    std::vector<double> r(static_cast<std::size_t>(m.cols()));
    for (Eigen::Index j = 0; j < m.cols(); ++j) r[static_cast<std::size_t>(j)] = m(i, j);
    rows.push_back(r);
  }
  return rows;
}

std::vector<double> vector_of(const Eigen::VectorXd& v) { return std::vector<double>(v.data(), v.data() + v.size()); }

}  // namespace

identify::StateSpace Identification::state_space() const {
  return identify::state_space(problem_->model(), coefficients_at(*problem_, result_.estimate));
}

identify::ModalModel Identification::modal_model() const {
  return identify::modal_model(problem_->model(), coefficients_at(*problem_, result_.estimate));
}

nlohmann::json Identification::model_json() const {
  const identify::StateSpace s = state_space();
  const identify::ModalModel m = modal_model();
  nlohmann::json units_in = nlohmann::json::array(), units_out = nlohmann::json::array();
  for (const auto& in : problem_->scenario.inputs) units_in.push_back(in.unit);
  for (const auto& se : problem_->scenario.sensors) units_out.push_back(se.unit);
  std::vector<double> hz;
  for (Eigen::Index k = 0; k < m.omega.size(); ++k) hz.push_back(m.omega[k] / (2.0 * M_PI));
  nlohmann::json zeta = nlohmann::json::array();
  for (Eigen::Index k = 0; k < m.zeta.size(); ++k) zeta.push_back(std::isfinite(m.zeta[k]) ? nlohmann::json(m.zeta[k]) : nlohmann::json());
  return {{"scenario", problem_->scenario.name},
          {"estimate", problem_->params->physical(result_.estimate)},
          {"converged", converged()},
          {"state_space", {{"A", matrix_json(s.A)}, {"B", matrix_json(s.B)}, {"C", matrix_json(s.C)}, {"D", matrix_json(s.D)},
                           {"inputs", s.inputs}, {"outputs", s.outputs}, {"input_units", units_in}, {"output_units", units_out},
                           {"states", "x = (u, du/dt): the FE model's degrees of freedom, then their rates"}}},
          {"modal", {{"frequency_hz", hz}, {"omega", vector_of(m.omega)}, {"zeta", zeta}, {"output_shapes", matrix_json(m.output_shapes)},
                     {"input_shapes", matrix_json(m.input_shapes)}, {"inputs", m.inputs}, {"outputs", m.outputs}}}};
}

namespace {

io::MatVariable mat_of(const std::string& name, const Eigen::MatrixXd& m) {
  io::MatVariable v;
  v.name = name;
  v.rows = static_cast<std::size_t>(m.rows());
  v.cols = static_cast<std::size_t>(m.cols());
  v.values.assign(m.data(), m.data() + m.size());  // column-major, as MATLAB stores it
  return v;
}

io::MatVariable mat_of(const std::string& name, const std::vector<std::string>& s) {
  io::MatVariable v;
  v.name = name;
  v.strings = s;
  v.is_strings = true;
  return v;
}

}  // namespace

void Identification::export_model(const std::string& path) const {
  io::check_output_file("export model", path, {});  // a file name in a directory that takes one
  // Never over what the identification read (its scenario file, its data file).
  for (const std::string& in : {problem_->scenario.source, problem_->data_source}) {
    std::error_code ec;
    if (!in.empty() && std::filesystem::is_regular_file(in, ec) && io::same_file(path, in))
      throw io::InputError("export model: '" + io::shorten(path) + "' is an input of this identification; it would be overwritten");
  }
  const std::string ext = std::filesystem::path(path).extension().string();
  if (ext == ".json") return io::write_json_atomic(path, model_json());
  if (ext != ".mat") throw io::InputError("export model: '" + path + "' must end in .json or .mat");
  const identify::StateSpace s = state_space();
  const identify::ModalModel m = modal_model();
  io::write_mat_file(path, {mat_of("A", s.A), mat_of("B", s.B), mat_of("C", s.C), mat_of("D", s.D), mat_of("inputs", s.inputs),
                            mat_of("outputs", s.outputs), mat_of("omega", m.omega), mat_of("zeta", m.zeta),
                            mat_of("output_shapes", m.output_shapes), mat_of("input_shapes", m.input_shapes)});
}

void Identification::write(io::RunDirectory& dir) const { identify::write_outputs(dir, *problem_, result_); }

void Identification::write(const std::string& dir) const {
  io::check_inputs_outside("write", dir, {problem_->scenario.source, problem_->data_source});
  io::RunDirectory run_dir(dir, output_files(), "scoleid");
  write(run_dir);
  run_dir.commit();
}

std::shared_ptr<identify::Problem> prepare(const io::Scenario& scenario, const DataSource& data, bool verbose) {
  io::validate_scenario(scenario);
  if (data.table) {
    io::check_table(*data.table);  // a table built in memory passes the checks a file's does
    return identify::make_problem(scenario, *data.table, data.name, data.meta ? &*data.meta : nullptr, data.meta_name.empty() ? data.name + " (metadata)" : data.meta_name, verbose);
  }
  return identify::make_problem(scenario, data.csv, verbose);
}

Identification identify_parameters(std::shared_ptr<identify::Problem> problem, const IdentifyOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) throw io::InputError("identify options: " + why);
  identify::RunOptions ro;
  ro.method = options.method;
  ro.max_iterations = options.max_iterations;
  ro.compute_std = options.compute_std;
  ro.verbose = options.verbose;
  ro.keep_interrupted = options.keep_interrupted;
  identify::RunResult r = identify::run_identification(*problem, ro);
  return Identification(std::move(problem), std::move(r));
}

Identification identify_parameters(const io::Scenario& scenario, const DataSource& data, const IdentifyOptions& options) {
  return identify_parameters(prepare(scenario, data), options);
}

}  // namespace scoleid
