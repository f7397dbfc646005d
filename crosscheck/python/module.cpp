// scoleid._core: the library's front doors for Python (README "From Python"). The package
// scoleid (scoleid/__init__.py) wraps it: scenarios as names, files, YAML text or dicts; data as
// dicts of numpy arrays, DataFrames or files. Only the public calls are bound — simulate_truth,
// identify_parameters with its Identification, the cross-check's mode and trajectory comparisons —
// nothing below them.
//
// Errors: io::InputError becomes scoleid.InputError (a ValueError) with the same one-line message;
// SIGINT during a call ends the solve under way (the library's interrupt checks) and raises
// KeyboardInterrupt. Long calls release the GIL.
#include <pybind11/complex.h>
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <chrono>
#include <complex>
#include <map>
#include <memory>
#include <csignal>
#include <exception>
#include <pthread.h>
#include <stdexcept>
#include <mutex>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include "scoleid/crosscheck/modes.h"
#include "scoleid/crosscheck/trajectories.h"
#include "scoleid/identify.h"
#include "scoleid/io/data_source.h"
#include "scoleid/io/error.h"
#include "scoleid/io/frf_record.h"
#include "scoleid/io/interrupt.h"
#include "scoleid/io/progress.h"
#include "scoleid/io/builtin.h"
#include "scoleid/io/scenario.h"
#include "scoleid/io/validation.h"
#include "scoleid/truth.h"

namespace py = pybind11;
using namespace scoleid;

namespace {

// For the duration of one call: the GIL released, then one library call at a time (the signal
// handlers and the interrupt flag are the process's), the library's SIGINT/SIGTERM recorder in
// place of Python's handlers (restored after). A call from within a call (a progress callback
// calling the library) is refused at once: it would wait for itself. A process forked while
// another thread is inside a call gets a fresh lock (the child has no such thread).
std::mutex* g_call_mutex = new std::mutex;
thread_local bool t_in_call = false;

std::mutex& call_mutex() { return *g_call_mutex; }

void reset_after_fork() {
  g_call_mutex = new std::mutex;  // the parent's may be held by a thread the child does not have (leaked: it cannot be destroyed)
  t_in_call = false;
}

// Marks the calling thread as inside a library call; refuses a second one on the same thread.
class ReentryGuard {
public:
  ReentryGuard() {
    if (t_in_call)
      throw std::runtime_error("scoleid: a library call cannot be made from within another (e.g. from a progress callback)");
    t_in_call = true;
  }
  ~ReentryGuard() { t_in_call = false; }
  ReentryGuard(const ReentryGuard&) = delete;
  ReentryGuard& operator=(const ReentryGuard&) = delete;
};

class LibraryCall {
public:
  LibraryCall() {
    io::clear_interrupt();
    sigaction(SIGINT, nullptr, &old_int_);
    sigaction(SIGTERM, nullptr, &old_term_);
    io::install_interrupt_handlers();
  }
  ~LibraryCall() {
    sigaction(SIGINT, &old_int_, nullptr);
    sigaction(SIGTERM, &old_term_, nullptr);
    // A signal in the moment between finish() and here goes to Python's own handler (the next
    // call's start would otherwise forget it); while an exception leaves the call it is that one's.
    if (io::interrupt_signal() != 0 && std::uncaught_exceptions() == 0) {
      io::clear_interrupt();
      PyErr_SetInterrupt();
    }
  }
  // After the call's work: a signal that came after its last check (the work finished all the
  // same) still ends the call, as KeyboardInterrupt: Ctrl-C during a call is never lost.
  void finish() {
    if (const int s = io::interrupt_signal()) throw io::Interrupted(s);
  }
  LibraryCall(const LibraryCall&) = delete;
  LibraryCall& operator=(const LibraryCall&) = delete;

private:
  ReentryGuard reentry_;                                    // first: a nested call is refused before it waits
  struct sigaction old_int_ {}, old_term_ {};
  py::gil_scoped_release release_;                          // constructed before the lock, released after it
  std::lock_guard<std::mutex> one_at_a_time_{call_mutex()};
};

// A scenario given as YAML text (source names it in messages), or with source empty as a built-in
// name or a file path, read as the programs read --scenario.
io::Scenario scenario_of(const std::string& yaml_text, const std::string& source) {
  io::Scenario sc = source.empty() ? io::load_scenario(yaml_text) : io::parse_scenario(yaml_text, source);
  io::validate_scenario(sc);
  return sc;
}

// A record as (names, t, values[samples x columns]).
py::tuple record(const io::DataTable& tab) {
  py::array_t<double> t(static_cast<py::ssize_t>(tab.t.size()));
  std::memcpy(t.mutable_data(), tab.t.data(), tab.t.size() * sizeof(double));
  py::array_t<double> v({static_cast<py::ssize_t>(tab.t.size()), static_cast<py::ssize_t>(tab.names.size())});
  auto w = v.mutable_unchecked<2>();
  for (std::size_t j = 0; j < tab.names.size(); ++j)
    for (std::size_t k = 0; k < tab.t.size(); ++k) w(static_cast<py::ssize_t>(k), static_cast<py::ssize_t>(j)) = tab.columns[j][k];
  return py::make_tuple(tab.names, t, v);
}

// A table given as a header (the time column's name among them) and its columns, read as the CSV
// reader reads a file with that header: the time column the one named (`time_column`, else the
// scenario's data.time_column, else "t" when there is one, else the first), units from the names'
// bracketed suffixes and the scenario's data.time_unit, the time converted into seconds.
io::DataTable table_of(const io::Scenario& sc, const std::vector<std::string>& header,
                       const py::array_t<double, py::array::c_style | py::array::forcecast>& values, const std::string& time_column,
                       const std::string& source) {
  if (values.ndim() != 2 || values.shape(1) != static_cast<py::ssize_t>(header.size()))
    throw io::InputError(source + ": expected samples x " + std::to_string(header.size()) + " values");
  std::vector<std::vector<double>> columns(header.size(), std::vector<double>(static_cast<std::size_t>(values.shape(0))));
  const auto v = values.unchecked<2>();
  for (py::ssize_t k = 0; k < values.shape(0); ++k)
    for (std::size_t j = 0; j < header.size(); ++j) columns[j][static_cast<std::size_t>(k)] = v(k, static_cast<py::ssize_t>(j));
  io::CsvOptions o{time_column.empty() ? sc.data.time_column : time_column, sc.data.time_unit};
  if (o.time_column.empty() && std::find(header.begin(), header.end(), "t") != header.end()) o.time_column = "t";
  return io::table_from_columns(header, columns, source, o);
}

py::tuple truth(const std::string& yaml_text, const std::string& source, bool progress) {
  const io::Scenario sc = scenario_of(yaml_text, source);
  TruthOptions o;
  o.progress = progress;
  Truth tr;
  {
    LibraryCall call;
    tr = simulate_truth(sc, o);
    call.finish();
  }
  return py::make_tuple(record(tr.table), io::to_json(tr.meta).dump());
}

struct IdentifyArgs {
  std::string data_file;                 // "" = not a file
  std::optional<std::vector<std::string>> header;  // an in-memory table: its column names (time among them)
  std::optional<py::array_t<double, py::array::c_style | py::array::forcecast>> values;  // samples x header
  std::string time_column;               // the time column's name ("" = as a CSV's: see table_of)
  std::string source = "data";           // the table's name in messages
  std::string meta_json;                 // truth.json text for an in-memory table ("" = none)
  std::string meta_source = "data (truth metadata)";  // where that came from, for messages
  std::optional<std::string> method;
  std::optional<int> max_iterations;
  bool compute_std = true, verbose = false;
  py::object progress = py::none();      // called with each progress line (verbose output)
};

// Progress lines to a Python callable for the duration of a call. The callable runs with the GIL
// held; an exception it raises ends the run (as an interrupt would) and is raised in its place.
class PythonProgress {
public:
  explicit PythonProgress(py::object callback) {
    if (callback.is_none()) return;
    callback_ = std::move(callback);
    sink_.emplace([this](const std::string& line) {
      py::gil_scoped_acquire gil;
      if (error_) return;
      try {
        callback_(line);
      } catch (py::error_already_set& e) {
        error_ = std::make_unique<py::error_already_set>(std::move(e));
        io::request_interrupt(SIGINT);
      }
    });
  }
  ~PythonProgress() { sink_.reset(); }
  PythonProgress(const PythonProgress&) = delete;
  PythonProgress& operator=(const PythonProgress&) = delete;
  // The callback's exception, if it raised one (call with the GIL held).
  void rethrow() {
    if (!error_) return;
    io::clear_interrupt();
    auto e = std::move(error_);
    throw std::move(*e);
  }

private:
  py::object callback_;
  std::unique_ptr<py::error_already_set> error_;
  std::optional<io::ProgressSink> sink_;
};

// The identification and the seconds the library call took (scenario parsing to the verdict).
py::tuple identify_call(const std::string& yaml_text, const std::string& source, const IdentifyArgs& a) {
  const auto start = std::chrono::steady_clock::now();
  io::Scenario sc = scenario_of(yaml_text, source);
  IdentifyOptions o;
  if (a.method) {
    const auto m = io::parse<io::Method>(*a.method);
    if (!m) throw io::InputError("identify: method must be one of " + io::names_joined<io::Method>(", ") + ", got '" + *a.method + "'");
    o.method = *m;
  }
  if (a.max_iterations) {
    o.max_iterations = *a.max_iterations;
    sc.identification.max_iterations = *a.max_iterations;
    io::validate_scenario(sc);
  }
  o.compute_std = a.compute_std;
  o.verbose = a.verbose || !a.progress.is_none();
  DataSource data = DataSource::synthetic();
  if (!a.data_file.empty()) data = DataSource::file(a.data_file);
  if (a.header) {
    std::optional<io::TruthMeta> meta;
    if (!a.meta_json.empty()) meta = io::truth_meta_from_json(nlohmann::json::parse(a.meta_json), a.meta_source);
    data = DataSource::in_memory(table_of(sc, *a.header, *a.values, a.time_column, a.source), a.source, meta, a.meta_source);
  }
  std::optional<Identification> id;
  PythonProgress progress(a.progress);
  try {
    LibraryCall call;
    id.emplace(identify_parameters(sc, data, o));
    call.finish();
  } catch (const io::Interrupted&) {
    progress.rethrow();  // the callback's own exception, when it was the callback that ended the run
    throw;
  }
  progress.rethrow();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return py::make_tuple(std::move(*id), seconds);
}

py::dict state_space(const Identification& id) {
  const identify::StateSpace s = id.state_space();
  py::dict d;
  d["A"] = s.A;
  d["B"] = s.B;
  d["C"] = s.C;
  d["D"] = s.D;
  d["inputs"] = s.inputs;
  d["outputs"] = s.outputs;
  return d;
}

py::dict modal_model(const Identification& id) {
  const identify::ModalModel m = id.modal_model();
  py::dict d;
  d["omega"] = m.omega;
  d["zeta"] = m.zeta;
  d["output_shapes"] = m.output_shapes;
  d["input_shapes"] = m.input_shapes;
  d["inputs"] = m.inputs;
  d["outputs"] = m.outputs;
  return d;
}

// fit.csv's table as (names, t, values[samples x columns]).
py::tuple fit_table(const Identification& id) {
  io::DataTable tab;
  {
    LibraryCall call;
    tab = id.fit_table();
    call.finish();
  }
  return record(tab);
}

std::string crosscheck_modes(const std::string& yaml_text, const std::string& source, int count, int segments, int elements, int levels) {
  const io::Scenario sc = scenario_of(yaml_text, source);
  crosscheck::ModesOptions o;
  o.count = count;
  o.segments = segments;
  o.elements = elements;
  o.levels = levels;
  std::string why;
  if (!o.IsValid(&why)) throw io::InputError("crosscheck_modes: " + why);
  LibraryCall call;
  std::string out = crosscheck::to_json(crosscheck::compare_modes(sc, o)).dump();
  call.finish();
  return out;
}

py::tuple crosscheck_trajectories(const std::string& yaml_text, const std::string& source, int segments, int levels, int elements,
                                  const std::string& truth_root) {
  const io::Scenario sc = scenario_of(yaml_text, source);
  crosscheck::TrajectoryOptions o;
  o.segments = segments;
  o.levels = levels;
  o.elements = elements;
  std::string why;
  if (!o.IsValid(&why)) throw io::InputError("crosscheck_trajectories: " + why);
  crosscheck::TrajectoryReport r;
  {
    LibraryCall call;
    r = crosscheck::compare_trajectories(sc, o, truth_root);
    call.finish();
  }
  py::array_t<double> t(static_cast<py::ssize_t>(r.t.size()));
  std::memcpy(t.mutable_data(), r.t.data(), r.t.size() * sizeof(double));
  return py::make_tuple(crosscheck::to_json(r).dump(), t, Eigen::MatrixXd(r.chain), Eigen::MatrixXd(r.fe));
}

// A data file as read_data reads it (scole-identify --data): (names, units, t, values).
py::tuple read_data_file(const std::string& path, const std::string& time_column, const std::string& time_unit) {
  io::DataTable tab;
  {
    LibraryCall call;
    tab = io::read_data(path, io::CsvOptions{time_column, time_unit});
    call.finish();
  }
  std::vector<std::string> units = tab.units;
  units.resize(tab.names.size());
  const py::tuple r = record(tab);
  return py::make_tuple(r[0], units, r[1], r[2]);
}

// A record's FRFs (io/frf_record.h, scole-data frf): (f, names, H, variance, coherence or None,
// orders, sample_rate, samples, segments, effective_averages, note, decay).
py::tuple frf_of_file(const std::string& path, const std::string& input, const std::vector<std::string>& responses,
                      const std::map<std::string, std::string>& units, double sample_rate, const std::string& estimator,
                      double segment, double overlap, const std::string& window, double f_min, double f_max,
                      const std::vector<double>& lines, const std::string& time_column, const std::string& time_unit,
                      double decay, const std::map<std::string, double>& noise) {
  io::RecordFrfOptions o;
  o.input = input;
  o.responses = responses;
  o.units = units;
  o.sample_rate = sample_rate;
  if (estimator == "h1") o.estimator = io::RecordFrfEstimator::H1;
  else if (estimator == "h2") o.estimator = io::RecordFrfEstimator::H2;
  else if (estimator == "lines") o.estimator = io::RecordFrfEstimator::Lines;
  else if (estimator == "impact") o.estimator = io::RecordFrfEstimator::Impact;
  else throw io::InputError("frf: estimator must be 'h1', 'h2', 'lines' or 'impact', got '" + io::one_line(estimator) + "'");
  o.decay = decay;
  o.noise = noise;
  if (window == "hann") o.window = io::FrfWindow::Hann;
  else if (window == "rectangular") o.window = io::FrfWindow::Rectangular;
  else throw io::InputError("frf: window must be 'hann' or 'rectangular', got '" + io::one_line(window) + "'");
  o.segment = segment;
  o.overlap = overlap;
  o.f_min = f_min;
  o.f_max = f_max;
  o.lines_hz = lines;
  io::RecordFrf r;
  {
    LibraryCall call;
    r = io::frf_of_record(path, io::CsvOptions{time_column, time_unit}, o);
    call.finish();
  }
  const auto L = static_cast<py::ssize_t>(r.data.f_hz.size()), S = static_cast<py::ssize_t>(r.data.channels.size());
  py::array_t<double> f(L);
  std::memcpy(f.mutable_data(), r.data.f_hz.data(), r.data.f_hz.size() * sizeof(double));
  py::array_t<std::complex<double>> H({L, S});
  py::array_t<double> var({L, S});
  auto h = H.mutable_unchecked<2>();
  auto v = var.mutable_unchecked<2>();
  bool coherent = S > 0;
  std::vector<std::string> names;
  for (py::ssize_t s = 0; s < S; ++s) {
    const auto& ch = r.data.channels[static_cast<std::size_t>(s)];
    names.push_back(ch.sensor);
    coherent = coherent && !ch.coherence.empty();
    for (py::ssize_t k = 0; k < L; ++k) h(k, s) = ch.H[static_cast<std::size_t>(k)], v(k, s) = ch.variance[static_cast<std::size_t>(k)];
  }
  py::object coherence = py::none();
  if (coherent) {
    py::array_t<double> c({L, S});
    auto w = c.mutable_unchecked<2>();
    for (py::ssize_t s = 0; s < S; ++s)
      for (py::ssize_t k = 0; k < L; ++k) w(k, s) = r.data.channels[static_cast<std::size_t>(s)].coherence[static_cast<std::size_t>(k)];
    coherence = c;
  }
  return py::make_tuple(f, names, H, var, coherence, r.orders, r.sample_rate, r.samples, r.segments, r.effective_averages, r.note,
                        r.data.decay);
}

}  // namespace

PYBIND11_MODULE(_core, m) {
  m.doc() = "scoleid's library calls (use the scoleid package, which wraps them)";
  static py::exception<io::InputError> input_error(m, "InputError", PyExc_ValueError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const io::InputError& e) {
      PyErr_SetString(input_error.ptr(), io::one_line(e.what()).c_str());
    } catch (const io::Interrupted& e) {
      PyErr_SetString(PyExc_KeyboardInterrupt, e.what());
    }
  });
  m.attr("__version__") = SCOLEID_VERSION;
  pthread_atfork(nullptr, nullptr, &reset_after_fork);
  m.def("builtin_scenarios", &io::builtin_scenario_names);
  m.def("builtin_scenario_description", &io::builtin_scenario_description);
  m.def("builtin_scenario", &io::builtin_scenario_text);
  m.def("scenario_json", [](const std::string& text, const std::string& source) { return io::to_json(scenario_of(text, source)).dump(); });
  m.def("truth", &truth, py::arg("yaml"), py::arg("source"), py::arg("progress") = false);
  py::class_<IdentifyArgs>(m, "IdentifyArgs")
      .def(py::init<>())
      .def_readwrite("data_file", &IdentifyArgs::data_file)
      .def_readwrite("header", &IdentifyArgs::header)
      .def_readwrite("values", &IdentifyArgs::values)
      .def_readwrite("time_column", &IdentifyArgs::time_column)
      .def_readwrite("source", &IdentifyArgs::source)
      .def_readwrite("progress", &IdentifyArgs::progress)
      .def_readwrite("meta_json", &IdentifyArgs::meta_json)
      .def_readwrite("meta_source", &IdentifyArgs::meta_source)
      .def_readwrite("method", &IdentifyArgs::method)
      .def_readwrite("max_iterations", &IdentifyArgs::max_iterations)
      .def_readwrite("compute_std", &IdentifyArgs::compute_std)
      .def_readwrite("verbose", &IdentifyArgs::verbose);
  py::class_<Identification>(m, "Identification")
      .def_property_readonly("names", &Identification::names)
      .def_property_readonly("estimate_vector", [](const Identification& id) { return Eigen::VectorXd(id.estimate()); })
      .def_property_readonly("converged", &Identification::converged)
      .def_property_readonly("verdict", &Identification::verdict)
      .def_property_readonly("exit_code", &Identification::exit_code)
      .def_property_readonly("warnings", &Identification::warnings)
      .def("to_json", [](const Identification& id) { return id.to_json().dump(); })
      .def("report", &Identification::FullReport)
      .def("model_json", [](const Identification& id) { return id.model_json().dump(); })
      .def("export_model", &Identification::export_model)
      .def("state_space", &state_space)
      .def("modal_model", &modal_model)
      .def("fit_table", &fit_table)
      .def("write", [](const Identification& id, const std::string& dir) { id.write(dir); });
  m.def("identify", &identify_call, py::arg("yaml"), py::arg("source"), py::arg("args"));
  m.def("read_data", &read_data_file);
  m.def("frf", &frf_of_file);
  m.def("crosscheck_modes", &crosscheck_modes);
  m.def("crosscheck_trajectories", &crosscheck_trajectories);
}
