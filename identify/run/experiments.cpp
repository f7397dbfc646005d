#include "scoleid/identify/door/scenario_door.h"
#include "scoleid/identify/run/experiments.h"
#include "scoleid/identify/point_failure.h"
#include "scoleid/identify/run/assessment.h"
#include "scoleid/identify/run/strategy.h"

#include <yaml-cpp/yaml.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <set>

#include "scoleid/identify/inverse/joint_misfit.h"
#include "scoleid/identify/inverse/modal_misfit.h"
#include "scoleid/identify/run/fit_plot.h"
#include "scoleid/identify/run/identify_run.h"
#include "scoleid/io/data_files.h"
#include "scoleid/io/data_source.h"
#include "scoleid/io/error.h"
#include "scoleid/io/number.h"
#include "scoleid/io/output_paths.h"
#include "scoleid/io/input_file.h"
#include "scoleid/io/limits.h"
#include "scoleid/io/validation.h"
#include <stdexcept>
#include "scoleid/io/interrupt.h"
#include "scoleid/io/validation.h"
#include "scoleid/io/progress.h"

namespace scoleid::identify {

namespace {

namespace fs = std::filesystem;

[[noreturn]] void bad(const std::string& file, const std::string& field, const std::string& what, const std::string& value) {
  io::fail_field(file, field, what, value);
  throw io::InputError(file);  // not reached
}

std::string scalar(const YAML::Node& n, const std::string& file, const std::string& field) {
  if (!n.IsScalar()) bad(file, field, "must be a text value", YAML::Dump(n));
  return n.Scalar();
}

// A scenario reference: a built-in name, or a file relative to the experiments file.
std::string resolve(const std::string& value, const std::string& file) {
  if (!io::builtin_scenario_yaml(value).empty()) return value;
  const fs::path p(value);
  return p.is_absolute() ? value : (fs::path(file).parent_path() / p).string();
}

std::string relative_path(const std::string& value, const std::string& file) {
  const fs::path p(value);
  return p.is_absolute() ? value : (fs::path(file).parent_path() / p).string();
}

// A name of at most kMaxNameLength characters: letters, digits and `extra`; when `alnum_first`, its
// first character a letter or digit.
bool name_of(const std::string& name, const std::string& extra, bool alnum_first) {
  if (name.empty() || name.size() > io::limits::kMaxNameLength) return false;
  for (std::size_t i = 0; i < name.size(); ++i) {
    const bool alnum = std::isalnum(static_cast<unsigned char>(name[i])) != 0;
    if (!alnum && (extra.find(name[i]) == std::string::npos || (i == 0 && alnum_first))) return false;
  }
  return true;
}

// A finite number.
double number(const YAML::Node& n, const std::string& file, const std::string& field) {
  const std::string text = scalar(n, file, field);
  double v = 0.0;
  if (!io::parse_decimal(text, v) || !std::isfinite(v)) bad(file, field, "must be a finite decimal number", text);
  return v;
}

// modes: {file, scenario} and, for a Universal File's modes, their standard deviations and the
// stations (io/uff_modes.h).
void parse_modes(const YAML::Node& m, const std::string& path, ExperimentsSpec& s) {
  if (!m.IsMap()) bad(path, "modes", "must be a mapping {file, scenario, ...}", YAML::Dump(m));
  auto& u = s.modes_uff;
  u.source = path;
  for (const auto& kv : m) {
    const std::string key = kv.first.Scalar(), f = "modes." + key;
    if (key == "file" || key == "scenario") continue;
    s.modes_uff_given = true;
    if (key == "frequency_std") u.frequency_std = number(kv.second, path, f);
    else if (key == "damping_std") u.damping_std = number(kv.second, path, f);
    else if (key == "shape_std") u.shape_std = number(kv.second, path, f);
    else if (key == "stations") {
      if (!kv.second.IsMap()) bad(path, f, "must be a mapping {sensor: <node><sign><axis>}", YAML::Dump(kv.second));
      for (const auto& st : kv.second) u.stations.emplace_back(st.first.Scalar(), scalar(st.second, path, f + "." + st.first.Scalar()));
    } else {
      bad(path, f, "is not a field of modes (file, scenario; for a Universal File: frequency_std, damping_std, shape_std, stations)", key);
    }
  }
  if (!m["file"]) bad(path, "modes.file", "is required (the measured modes: CSV, or a Universal File's datasets 55)", "missing");
  s.modes_file = relative_path(scalar(m["file"], path, "modes.file"), path);
  if (m["scenario"]) s.modes_scenario = resolve(scalar(m["scenario"], path, "modes.scenario"), path);
}

// The measured modes: a Universal File's datasets 55 with the stated deviations, or the CSV.
io::ModalData read_modes(const ExperimentsSpec& spec) {
  if (io::is_uff_file(*spec.modes_file)) return io::modal_data_from_uff(io::uff::read_file(*spec.modes_file), spec.modes_uff);
  if (spec.modes_uff_given)
    bad(spec.source, "modes", "frequency_std, damping_std, shape_std and stations describe a Universal File's modes; " + *spec.modes_file +
                                  " is a CSV, which states its own", "a CSV");
  return io::read_modal_data(*spec.modes_file);
}

}  // namespace

ExperimentsSpec load_experiments(const std::string& path) {
  ExperimentsSpec s;
  s.source = path;
  if (!fs::is_regular_file(path)) bad(path, "file", "does not exist or is not a file", path);
  YAML::Node root;
  try {
    const std::string text = io::read_text_file(path, "experiments file");
    io::check_yaml_nesting(text, "experiments file '" + path + "'");
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    bad(path, "yaml", "is not valid YAML", io::one_line(e.what()));
  }
  io::check_yaml_document(root, "experiments file '" + path + "'", true);
  if (!root.IsMap()) bad(path, "document", "must be a mapping with experiments, runs and/or modes", YAML::Dump(root));
  for (const auto& kv : root) {
    const std::string key = kv.first.Scalar();
    if (key != "experiments" && key != "description" && key != "threads" && key != "runs" && key != "modes")
      bad(path, key, "is not a field of an experiments file (experiments, description, threads, runs, modes)", key);
  }
  if (!root["experiments"]) bad(path, "experiments", "is required (the name of the run)", "missing");
  s.name = scalar(root["experiments"], path, "experiments");
  if (!name_of(s.name, "_.-", true))
    bad(path, "experiments", "must start with a letter or digit, then letters, digits, '_', '-' or '.' (at most " +
                                 std::to_string(io::limits::kMaxNameLength) + ")", io::one_line(s.name.substr(0, 80)));
  if (root["description"]) s.description = scalar(root["description"], path, "description");
  if (root["threads"]) {
    const std::string t = scalar(root["threads"], path, "threads");
    double v = -1.0;
    if (!io::parse_decimal(t, v) || v != std::floor(v) || !(v >= 0 && v <= 1024))
      bad(path, "threads", "must be an integer in [0, 1024]", t);
    s.threads = static_cast<int>(v);
    // The command line's bound (--threads): more threads than that is no machine's.
    if (s.threads < 0 || s.threads > 1024)
      bad(path, "threads", "must be an integer in [0, 1024] (0 = the machine's threads)", std::to_string(s.threads));
  }
  std::set<std::string> names;
  if (root["runs"]) {
    if (!root["runs"].IsSequence()) bad(path, "runs", "must be a list of {name, scenario, data}", YAML::Dump(root["runs"]));
    int i = 0;
    for (const auto& r : root["runs"]) {
      const std::string f = "runs[" + std::to_string(i++) + "]";
      if (!r.IsMap()) bad(path, f, "must be a mapping {name, scenario, data}", YAML::Dump(r));
      for (const auto& kv : r) {
        const std::string key = kv.first.Scalar();
        if (key != "name" && key != "scenario" && key != "data")
          bad(path, f + "." + key, "is not a field of a run (name, scenario, data)", key);
      }
      ExperimentsSpec::Run run;
      if (!r["name"]) bad(path, f + ".name", "is required", "missing");
      run.name = scalar(r["name"], path, f + ".name");
      if (!name_of(run.name, "_-", false))
        bad(path, f + ".name", "must be letters, digits, '_' or '-', at most " + std::to_string(io::limits::kMaxNameLength) +
                                   " (it names the run's output files)", io::one_line(run.name.substr(0, 80)));
      if (!names.insert(run.name).second) bad(path, f + ".name", "is used by two runs", run.name);
      if (run.name == "modes") bad(path, f + ".name", "is reserved for the modal data", run.name);
      if (!r["scenario"]) bad(path, f + ".scenario", "is required (a built-in name or a YAML file)", "missing");
      run.scenario = resolve(scalar(r["scenario"], path, f + ".scenario"), path);
      if (r["data"]) run.data = relative_path(scalar(r["data"], path, f + ".data"), path);
      // One record fitted twice would count its information twice (intervals half as wide).
      for (std::size_t k = 0; k < s.runs.size() && run.data; ++k)
        if (s.runs[k].data && io::same_file(*s.runs[k].data, *run.data))
          bad(path, f + ".data", "is the record of runs[" + std::to_string(k) + "] (" + s.runs[k].name +
                                     ") too: one record counted twice would halve the intervals", *run.data);
      s.runs.push_back(run);
    }
  }
  if (root["modes"]) parse_modes(root["modes"], path, s);
  if (s.runs.empty() && !s.modes_file) bad(path, "runs", "at least one run or a modes file is needed", "none");
  if (s.runs.empty() && s.modes_scenario.empty())
    bad(path, "modes.scenario", "is required when there are no runs (the model the modes are compared with)", "missing");
  return s;
}

std::unique_ptr<ExperimentsProblem> make_experiments(const ExperimentsSpec& spec) {
  auto ep = std::make_unique<ExperimentsProblem>();
  ep->spec = spec;
  const std::vector<std::string>* names = nullptr;
  VectorXd initial;
  std::string lead;
  auto same_parameters = [&](const Parameterization& p, const std::string& field) {
    if (!names) {
      names = &p.names();
      initial = p.initial();
      lead = field;
      return;
    }
    if (p.names() != *names)
      bad(spec.source, field, "must estimate the same parameters as " + lead, [&] {
        std::string s;
        for (const auto& n : p.names()) s += (s.empty() ? "" : ",") + n;
        return s;
      }());
    const VectorXd q0 = p.initial();
    for (Eigen::Index i = 0; i < q0.size(); ++i)
      if (!(std::abs(q0[i] - initial[i]) <= 1e-12 * std::abs(initial[i])))
        bad(spec.source, field, "must start from the same values as " + lead + " (" + (*names)[static_cast<std::size_t>(i)] + ")",
            std::to_string(q0[i]));
  };
  for (std::size_t i = 0; i < spec.runs.size(); ++i) {
    const auto& r = spec.runs[i];
    io::Scenario sc = io::load_scenario(r.scenario);
    io::validate_scenario(sc);
    if (sc.identification.smoothness != 0.0)
      bad(spec.source, "runs[" + std::to_string(i) + "].scenario", "sets identification.smoothness, which a joint run does not take",
          r.scenario);
    if (sc.identification.start != io::Start::Auto)
      bad(spec.source, "runs[" + std::to_string(i) + "].scenario",
          "sets identification.start, which a joint run does not take (it starts plain, without restarts)", r.scenario);
    if (!sc.identification.band.empty())
      bad(spec.source, "runs[" + std::to_string(i) + "].scenario",
          "sets identification.band, which a joint run does not take (its Fisher sum counts independent samples)", r.scenario);
    if (!sc.identification.uncertain.empty())
      bad(spec.source, "runs[" + std::to_string(i) + "].scenario",
          "sets identification.uncertain, which a joint run does not take (its interval has no consider terms)", r.scenario);
    if (sc.identification.model != io::Model::Linear)
      bad(spec.source, "runs[" + std::to_string(i) + "].scenario",
          std::string("sets identification.model: ") + io::to_string(sc.identification.model) + ", which a joint run does not take (linear model only)",
          r.scenario);
    sc.identification.band_mode = io::IdentificationSpec::BandMode::None;  // (a joint run takes no band; above)
    ep->runs.push_back(make_problem(sc, r.data));
    same_parameters(*ep->runs.back()->params, "runs[" + std::to_string(i) + "] (" + r.name + ")");
  }
  if (spec.modes_file) {
    ep->modes = read_modes(spec);
    ep->modes_scenario = std::make_unique<io::Scenario>(spec.modes_scenario.empty() ? ep->runs.front()->scenario
                                                                                      : io::load_scenario(spec.modes_scenario));
    io::validate_scenario(*ep->modes_scenario);
    if (!spec.modes_scenario.empty() && !ep->modes_scenario->identification.uncertain.empty())
      bad(spec.source, "modes.scenario",
          "sets identification.uncertain, which measured modes do not take (their interval has no consider terms)",
          spec.modes_scenario);
    ep->modes_structure = make_structure(*ep->modes_scenario, ep->modes_scenario->identification.elements);
    check_parameters(*ep->modes_structure, *ep->modes_scenario);
    ep->modes_params = ep->modes_structure->parameterize(*ep->modes_scenario);
    same_parameters(*ep->modes_params, "modes.scenario");
  }
  // Likelihood weights (header): with modal data beside time runs every run needs stated noise.
  bool all_stated = !ep->runs.empty();
  for (std::size_t i = 0; i < ep->runs.size(); ++i)
    for (std::size_t k = 0; k < ep->runs[i]->noise_std.size(); ++k)
      if (!(ep->runs[i]->noise_std[k] > 0)) {
        all_stated = false;
        if (spec.modes_file)
          bad(spec.source, "runs[" + std::to_string(i) + "] (" + spec.runs[i].name + ")",
              "sensor has no stated noise level (noise_std), needed to weigh its data against the modal data",
              ep->runs[i]->data.names[k]);
      }
  if (all_stated)
    for (auto& p : ep->runs) {
      const double W = p->data.white_noise_integral(p->data.t.front(), p->data.t.back());
      const auto n = static_cast<double>(p->data.t.size());
      p->objective_options.weights.clear();
      for (double sd : p->noise_std) p->objective_options.weights.push_back(n / (sd * sd * W));
    }
  // Modal data the model cannot be compared with at the start (fewer flexible modes than measured,
  // a measured mode no model mode can be matched to) are bad input, not a failed run.
  if (ep->modes) {
    check_modal_data(*ep->modes, *ep->modes_scenario);
    try {
      ModalMisfit probe(ep->modes_structure->model(), *ep->modes_params, *ep->modes);
      probe.cost(ep->modes_params->initial());
    } catch (const std::domain_error& e) {
      bad(*spec.modes_file, "modes", "cannot be compared with the model of " + ep->modes_scenario->name + " at the starting values",
          io::one_line(e.what()));
    }
  }
  return ep;
}

bool ExperimentsResult::converged() const {
  if (!summary.converged()) return false;
  for (const auto& e : experiments)
    if (!e.explains_data) return false;
  return true;
}

namespace {

// A time run's part of the joint result at the estimate: its fit test, residual RMS per sensor and,
// with compute_std, its own Fisher information.
FisherInformation time_experiment(Problem& p, Objective& obj, const VectorXd& estimate, bool compute_std,
                                  ExperimentsResult::Experiment& x) {
  FisherInformation fi;
  x.kind = "time";
  x.data_source = p.data_source;
  x.data_values = static_cast<long>(p.data.t.size()) * p.data.sensors();
  const FitTest f = test_fit(p, obj, estimate);
  x.explains_data = f.explains_data;
  x.fit_message = f.message;
  for (const auto& s : f.sensors) {
    x.channels.push_back(s.name);
    x.residual_rms.push_back(s.rms_residual);
  }
  if (compute_std) {
    fi = fisher_information(obj, sensors_with_noise(p), estimate);
  }
  x.counters = obj.counters();
  return fi;
}

// The modal data's part: χ² against its degrees of freedom, and its Fisher information.
FisherInformation modal_experiment(ModalMisfit& modal, const io::ModalData& modes, const std::string& file, int components,
                                   int parameters, const VectorXd& estimate, bool compute_std,
                                   ExperimentsResult::Experiment& x) {
  FisherInformation fi;
  x.kind = "modal";
  x.data_source = file;
  VectorXd res;
  modal.residuals(estimate, res);
  const auto N = static_cast<double>(res.size());
  x.data_values = static_cast<long>(res.size());
  const double chi2 = res.squaredNorm();
  // Degrees of freedom: a unit-normalised shape's residual has one component fewer than its
  // stations (it is orthogonal to the shape to first order); with the modes the only data the
  // P fitted parameters take P more.
  const double shapes = modes.has_shapes() ? static_cast<double>(modes.modes.size()) : 0.0;
  const double nu = std::max(1.0, N - shapes - (components == 1 ? static_cast<double>(parameters) : 0.0));
  x.explains_data = chi2 <= nu + 3.0 * std::sqrt(2.0 * nu);
  char buf[240];
  std::snprintf(buf, sizeof buf, "chi2 %.4g over %ld modal residuals, %.0f degrees of freedom (band up to %.4g)%s", chi2,
                x.data_values, nu, nu + 3.0 * std::sqrt(2.0 * nu),
                x.explains_data ? "" : ": the modes are not explained within their stated uncertainties");
  x.fit_message = buf;
  x.channels.push_back("all (in stated stds)");
  x.residual_rms.push_back(N > 0 ? std::sqrt(chi2 / N) : 0.0);
  if (compute_std) {
    fi.F = modal.fisher(estimate);
    fi.chi2 = chi2;
    fi.data_values = x.data_values;
    fi.systematic = std::max(0.0, chi2 - nu - 2.0 * std::sqrt(2.0 * nu));
    fi.stated_noise = true;
    fi.noise_std.clear();
  }
  return fi;
}

// Measured modes alone: the interval from the noise (the file's stds) and residual terms of the
// Fisher information (no half-record refit applies to a mode set; docs/theory.md §8.2), a parameter
// whose interval exceeds half its value flagged as the time-domain assessment flags it.
void modal_interval(ExperimentsResult& r, const ExperimentsProblem& ep) {
  IntervalInputs in;
  in.estimate = r.estimate;
  in.refit_applies = false;
  r.interval = uncertainty_interval(r.ident, in);
  r.interval.note = "measured modes alone: noise (the file's stds) and residual terms only, no half-record refit";
  for (std::size_t i = 0; i < r.names.size(); ++i) {
    const auto e = static_cast<Eigen::Index>(i);
    if (!r.ident.identifiable[i] || !r.interval.too_wide[i]) continue;
    r.ident.identifiable[i] = false;
    char buf[200];
    std::snprintf(buf, sizeof buf, "uncertainty interval ±%.3g is %.3g of the estimate: above 0.5 (the modes determine it only with others)",
                  r.interval.half_width[e], r.interval.half_width[e] / std::abs(r.estimate[e]));
    r.ident.reason[i] = buf;
  }
}

}  // namespace

ExperimentsResult run_experiments(ExperimentsProblem& ep, const ExperimentsOptions& eo) {
  const auto t_start = std::chrono::steady_clock::now();
  ExperimentsResult r;
  r.name = ep.spec.name;
  const io::Scenario& lead = ep.runs.empty() ? *ep.modes_scenario : ep.runs.front()->scenario;
  const Parameterization& params = ep.runs.empty() ? *ep.modes_params : *ep.runs.front()->params;
  r.names = params.names();
  r.initial = params.initial();
  // The true values where the data's origin states them (synthetic runs, truth.json beside a data
  // file); measured modes carry none.
  if (!ep.runs.empty()) r.truth = ep.runs.front()->true_values;
  r.weighting = !ep.runs.empty() && !ep.runs.front()->objective_options.weights.empty() ? "likelihood" : "relative";
  if (ep.runs.empty()) r.weighting = "likelihood";

  std::vector<std::unique_ptr<Objective>> objs;
  std::vector<JointMisfit::Component> parts;
  for (std::size_t i = 0; i < ep.runs.size(); ++i) {
    Problem& p = *ep.runs[i];
    ObjectiveOptions oo = p.objective_options;
    // Several parts are already solved side by side: one thread per sweep.
    if (ep.runs.size() + (ep.modes ? 1 : 0) > 1) oo.sweep_threads = 1;
    objs.push_back(std::make_unique<Objective>(p.model(), *p.params, p.signals, p.data, oo));
    parts.push_back({ep.spec.runs[i].name, objs.back().get()});
  }
  std::unique_ptr<ModalMisfit> modal;
  if (ep.modes) {
    modal = std::make_unique<ModalMisfit>(ep.modes_structure->model(), *ep.modes_params, *ep.modes);
    parts.push_back({"modes", modal.get()});
  }
  JointMisfitOptions jo;
  jo.threads = eo.threads.value_or(ep.spec.threads);
  JointMisfit joint(parts, jo);
  r.threads = joint.threads();

  // A joint run takes no smoothness prior (refused by make_experiments).
  r.method = resolve_method(eo.method.value_or(lead.identification.method), params.size(), false,
                            joint.has_matrix_free_products());
  if (r.method == io::Method::GaussNewtonKrylov && !joint.has_matrix_free_products())
    bad(ep.spec.source, "method", "needs displacement sensors only in every run", io::to_string(r.method));
  const OptimizerOptions oo = optimizer_options(lead.identification, r.method, params.size(), eo.max_iterations);
  if (eo.verbose) {
    io::progress("%5s", "iter");
    for (std::size_t i = 0; i < r.names.size() && i < 6; ++i) io::progress(" %13s", r.names[i].c_str());
    io::progress(" %13s %8s\n", "cost", "horizon");
  }
  auto progress = [&](const IterationRecord& rec) {
    io::check_interrupt();
    if (!eo.verbose) return;
    io::progress("%5d", rec.k);
    for (Eigen::Index i = 0; i < rec.q.size() && i < 6; ++i) io::progress(" %13.6g", rec.q[i]);
    io::progress(" %13.6e %8.4g\n", rec.cost, rec.horizon);
    std::fflush(stdout);
  };
  r.summary = minimize(joint, r.initial, oo, progress);
  r.estimate = r.summary.q;
  joint.set_horizon(1.0);
  double J = 0.0;
  try {
    J = joint.cost(r.estimate);
  } catch (const std::exception& e) {
    if (!point_failure(e)) throw;
    throw std::runtime_error("the model cannot be evaluated at the estimate (" + io::one_line(e.what()) + ")");
  }
  r.summary.cost = J;

  FisherInformation total;
  for (int e = 0; e < joint.components(); ++e) {
    ExperimentsResult::Experiment x;
    x.name = joint.name(e);
    x.cost = joint.last_costs()[static_cast<std::size_t>(e)];
    x.share = J > 0 ? x.cost / J : 0.0;
    const auto u = static_cast<std::size_t>(e);
    const FisherInformation fi =
        e < static_cast<int>(ep.runs.size())
            ? time_experiment(*ep.runs[u], *objs[u], r.estimate, eo.compute_std, x)
            : modal_experiment(*modal, *ep.modes, *ep.spec.modes_file, joint.components(), params.size(), r.estimate,
                               eo.compute_std, x);
    if (eo.compute_std) {
      x.alone = identifiability_from(fi, r.estimate);
      if (x.kind == "modal") x.alone.noise_source = "the modal data file's stds";
      total += fi;
    }
    r.experiments.push_back(std::move(x));
  }
  if (eo.compute_std) {
    r.ident = identifiability_from(total, r.estimate);
    if (r.weighting == "relative")
      r.std_note = "some noise levels are not stated: the runs are weighed by their relative misfit, not by the likelihood, "
                   "so the std (the Cramér-Rao bound with noise levels from the residual) may be optimistic";
    if (ep.runs.empty() && ep.modes) modal_interval(r, ep);
  }
  r.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  return r;
}

nlohmann::json ExperimentsResult::to_json() const {
  using nlohmann::json;
  auto finite = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
  auto per_param = [&](const VectorXd& v) {
    json o = json::object();
    for (std::size_t i = 0; i < names.size(); ++i)
      o[names[i]] = static_cast<Eigen::Index>(i) < v.size() ? finite(v[static_cast<Eigen::Index>(i)]) : json(nullptr);
    return o;
  };
  auto ident_json = [&](const Identifiability& id) {
    if (id.identifiable.empty()) return json{{"assessed", false}};
    json flags = json::object();
    for (std::size_t i = 0; i < names.size(); ++i) flags[names[i]] = id.identifiable[i] ? json(true) : json(id.reason[i]);
    return json{{"assessed", true},        {"std", per_param(id.std)},     {"resolution", per_param(id.resolution)},
                {"identifiable", flags},    {"condition_number", finite(id.condition_number)},
                {"chi2", id.chi2},          {"data_values", id.data_values}, {"noise_source", id.noise_source}};
  };
  json out;
  out["experiments"] = name;
  out["method"] = io::to_string(method);
  out["weighting"] = weighting;
  out["threads"] = threads;
  out["converged"] = converged();
  out["optimizer_converged"] = summary.converged();
  out["termination"] = to_string(summary.termination);
  out["message"] = summary.message;
  out["iterations"] = summary.iterations_done;
  out["cost"] = summary.cost;
  out["initial"] = per_param(initial);
  out["estimate"] = per_param(estimate);
  json t = json::object();
  for (const auto& [k, v] : truth) t[k] = v;
  out["truth"] = t;
  out["identifiability"] = ident_json(ident);
  if (!ident.identifiable.empty()) {
    out["identifiability"]["std_note"] = std_note;
    if (interval.half_width.size() == estimate.size()) {
      json iv = json::object();
      for (std::size_t i = 0; i < names.size(); ++i) {
        const auto e = static_cast<Eigen::Index>(i);
        const double w = interval.half_width[e];
        json x{{"half_width", finite(w)},
               {"low", std::isfinite(w) ? json(estimate[e] - w) : json(nullptr)},
               {"high", std::isfinite(w) ? json(estimate[e] + w) : json(nullptr)},
               {"noise_2std", finite(interval.noise[e])},
               {"residual_2resolution", finite(interval.residual[e])}};
        if (const auto t = truth.find(names[i]); t != truth.end() && std::isfinite(w))
          x["covers_truth"] = std::abs(estimate[e] - t->second) <= w;
        iv[names[i]] = x;
      }
      out["identifiability"]["interval"] = iv;
      out["identifiability"]["interval_note"] = interval.note;
    } else {
      out["identifiability"]["interval"] =
          "not assessed in a joint run with time records (no half-record refit, no consider terms): std and resolution "
          "are the Fisher information's of all experiments together";
    }
  }
  json ex = json::array();
  for (const auto& e : experiments) {
    json rms = json::object();
    for (std::size_t k = 0; k < e.channels.size(); ++k) rms[e.channels[k]] = finite(e.residual_rms[k]);
    ex.push_back({{"name", e.name},
                  {"kind", e.kind},
                  {"data", e.data_source},
                  {"cost", e.cost},
                  {"misfit_share", e.share},
                  {"data_values", e.data_values},
                  {"residual_rms", rms},
                  {"explains_data", e.explains_data},
                  {"fit_message", e.fit_message},
                  {"alone_at_joint_estimate", ident_json(e.alone)},
                  {"solves", {{"forward", e.counters.forward_solves},
                              {"costate", e.counters.costate_solves},
                              {"sensitivity", e.counters.sensitivity_solves}}}});
  }
  out["per_experiment"] = ex;
  json hist = json::array();
  for (const auto& it : summary.iterations) hist.push_back({{"k", it.k}, {"cost", it.cost}, {"q", per_param(it.q)}, {"horizon", it.horizon}});
  out["history"] = hist;
  out["wall_seconds"] = wall_seconds;
  return out;
}

std::vector<std::string> experiments_output_files(const ExperimentsSpec& spec) {
  std::vector<std::string> f = {"identify.json"};
  for (const auto& r : spec.runs)
    for (const char* ext : {".csv", ".gp", ".png"}) f.push_back("fit-" + r.name + ext);
  if (spec.modes_file) f.push_back("modes-fit.csv");
  return f;
}

void write_experiments_outputs(io::RunDirectory& dir, ExperimentsProblem& ep, const ExperimentsResult& r) {
  std::vector<std::pair<int, double>> cost;
  for (const auto& it : r.summary.iterations) cost.emplace_back(it.k, it.cost);
  std::vector<io::DataTable> tables(ep.runs.size());
  std::vector<FitPlot> plots;
  for (std::size_t i = 0; i < ep.runs.size(); ++i) {
    Problem& p = *ep.runs[i];
    const std::string base = "fit-" + ep.spec.runs[i].name;
    Objective obj(p.model(), *p.params, p.signals, p.data, p.objective_options);
    tables[i] = fit_table(p.data, obj.predict(r.estimate));
    io::write_csv(dir.path(base + ".csv"), tables[i]);
    io::write_text_atomic(dir.path(base + ".gp"), fit_plot_script(p.data.names, cost, base + ".csv", base + ".png"));
    plots.push_back(FitPlot{&tables[i], p.data.names, cost, base + ".png", {}});
  }
  // Every run's plot side by side, each from a raw float64 copy of its table.
  const std::vector<RenderStatus> rendered = render_fit_plots(dir.staging(), plots);
  for (std::size_t i = 0; i < rendered.size(); ++i)
    if (rendered[i] == RenderStatus::Failed)
      std::fprintf(stderr, "scole-identify: note: gnuplot could not render %s\n", plots[i].png.c_str());
  if (ep.modes) {
    ModalMisfit modal(ep.modes_structure->model(), *ep.modes_params, *ep.modes);
    const auto matches = modal.matches(r.estimate);
    const bool damping = ep.modes->has_damping(), shapes = ep.modes->has_shapes();
    std::string csv = "mode,frequency_hz_measured,frequency_hz_model,model_mode";
    if (shapes) csv += ",mac";
    csv += damping ? ",damping_ratio_measured,damping_ratio_model\n" : ",damping_ratio_model\n";
    char buf[400];
    for (const auto& m : matches) {
      const auto& meas = ep.modes->modes[static_cast<std::size_t>(m.measured)];
      std::snprintf(buf, sizeof buf, "%d,%.17g,%.17g,%d", meas.label, meas.frequency_hz, m.frequency_hz, m.model + 1);
      csv += buf;
      if (shapes) {
        std::snprintf(buf, sizeof buf, ",%.17g", m.mac);
        csv += buf;
      }
      if (damping) {
        std::snprintf(buf, sizeof buf, ",%.17g", meas.damping_ratio);
        csv += buf;
      }
      std::snprintf(buf, sizeof buf, ",%.17g\n", m.damping_ratio);
      csv += buf;
    }
    io::write_text_atomic(dir.path("modes-fit.csv"), csv);
  }
  io::write_json_atomic(dir.path("identify.json"), r.to_json());
}

}  // namespace scoleid::identify
