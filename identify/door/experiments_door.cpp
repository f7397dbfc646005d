// The identifier's front door for several experiments (experiments_door.h; docs/theory.md §6.5, §10.1b).
#include "scoleid/identify/door/experiments_door.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <filesystem>
#include <set>

#include "scoleid/identify/door/scenario_door.h"
#include "scoleid/identify/inverse/modal_misfit.h"
#include "scoleid/io/data_files.h"
#include "scoleid/io/data_source.h"
#include "scoleid/io/error.h"
#include "scoleid/io/input_file.h"
#include "scoleid/io/limits.h"
#include "scoleid/io/number.h"
#include "scoleid/io/output_paths.h"
#include "scoleid/io/validation.h"

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

// What a joint run does not take, in run i's scenario.
static void check_joint_run_scenario(const ExperimentsSpec& spec, std::size_t i, const io::Scenario& sc) {
  if (sc.identification.smoothness != 0.0)
    bad(spec.source, "runs[" + std::to_string(i) + "].scenario", "sets identification.smoothness, which a joint run does not take",
        spec.runs[i].scenario);
  if (sc.identification.start != io::Start::Auto)
    bad(spec.source, "runs[" + std::to_string(i) + "].scenario",
        "sets identification.start, which a joint run does not take (it starts plain, without restarts)", spec.runs[i].scenario);
  if (!sc.identification.band.empty())
    bad(spec.source, "runs[" + std::to_string(i) + "].scenario",
        "sets identification.band, which a joint run does not take (its Fisher sum counts independent samples)", spec.runs[i].scenario);
  if (!sc.identification.uncertain.empty())
    bad(spec.source, "runs[" + std::to_string(i) + "].scenario",
        "sets identification.uncertain, which a joint run does not take (its interval has no consider terms)", spec.runs[i].scenario);
  if (sc.identification.model != io::Model::Linear)
    bad(spec.source, "runs[" + std::to_string(i) + "].scenario",
        std::string("sets identification.model: ") + io::to_string(sc.identification.model) + ", which a joint run does not take (linear model only)",
        spec.runs[i].scenario);
}

// Likelihood weights (header): with modal data or frequency-domain runs beside time runs every time
// run needs stated noise (their misfits are ½χ² of stated variances).
static void set_likelihood_weights(const ExperimentsSpec& spec, ExperimentsProblem& ep) {
  bool all_stated = true, any_time = false, any_frf = false;
  for (const auto& p : ep.runs) (p->frf ? any_frf : any_time) = true;
  const char* beside = spec.modes_file ? "the modal data" : "the frequency-domain runs' FRFs";
  for (std::size_t i = 0; i < ep.runs.size(); ++i) {
    if (ep.runs[i]->frf) continue;
    for (std::size_t k = 0; k < ep.runs[i]->noise_std.size(); ++k)
      if (!(ep.runs[i]->noise_std[k] > 0)) {
        all_stated = false;
        if (spec.modes_file || any_frf)
          bad(spec.source, "runs[" + std::to_string(i) + "] (" + spec.runs[i].name + ")",
              std::string("sensor has no stated noise level (noise_std), needed to weigh its data against ") + beside,
              ep.runs[i]->data.names[k]);
      }
  }
  if (all_stated && any_time)
    for (auto& p : ep.runs) {
      if (p->frf) continue;
      const double W = p->data.white_noise_integral(p->data.t.front(), p->data.t.back());
      const auto n = static_cast<double>(p->data.t.size());
      p->objective_options.weights.clear();
      for (double sd : p->noise_std) p->objective_options.weights.push_back(n / (sd * sd * W));
    }
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
    check_joint_run_scenario(spec, i, sc);
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
  set_likelihood_weights(spec, *ep);
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

}  // namespace scoleid::identify
