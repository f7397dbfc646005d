#include "scoleid/io/data_source.h"
#include "scoleid/io/time_grid.h"
#include "scoleid/io/input_file.h"
#include "scoleid/io/lvm.h"
#include "scoleid/io/tdms.h"

#include <cmath>
#include <filesystem>
#include <fstream>

#include "scoleid/io/error.h"
#include "scoleid/io/limits.h"
#include "scoleid/io/uff.h"
#include "scoleid/io/units.h"
#include "scoleid/io/validation.h"

#include <nlohmann/json.hpp>

namespace scoleid::io {

bool is_uff_file(const std::string& path) { return uff::looks_like_uff(file_head(path, 4096)); }

namespace {

// The column description beside a converted CSV (kColumnsFormat), or null: a JSON file of the same
// stem that is not one (truth.json, a lab's own notes, one that does not parse) is not ours.
nlohmann::json sidecar_of(const std::string& path) {
  std::filesystem::path meta(path);
  meta.replace_extension(".json");
  std::error_code ec;
  if (meta == std::filesystem::path(path) || !std::filesystem::is_regular_file(meta, ec)) return nullptr;
  nlohmann::json j;
  try {
    j = read_json(meta.string());
  } catch (const InputError&) {
    return nullptr;
  }
  const auto f = j.is_object() ? j.find("format") : j.end();
  if (!j.is_object() || f == j.end() || !f->is_string() || f->get<std::string>() != kColumnsFormat) return nullptr;
  j["__path"] = meta.string();
  return j;
}

// Units from the sidecar where the header states none. It must describe exactly the CSV's columns.
void units_from_sidecar(DataTable& tab, const nlohmann::json& j) {
  const std::string meta = j["__path"].get<std::string>();
  const auto cols = j.find("columns");
  if (cols == j.end() || !cols->is_array()) throw InputError(meta + ": columns must be a list");
  tab.units.resize(tab.names.size());
  std::vector<bool> described(tab.names.size(), false);
  for (const auto& c : *cols) {
    if (!c.is_object() || !c.contains("name") || !c["name"].is_string() || (c.contains("unit") && !c["unit"].is_string()))
      throw InputError(meta + ": columns[]: each needs a name and a unit as text");
    const int k = tab.find(c["name"].get<std::string>());
    if (k < 0)
      throw InputError(meta + ": describes column '" + one_line(c["name"].get<std::string>()) + "', which '" + tab.source +
                       "' lacks; the two files are not from the same conversion");
    described[static_cast<std::size_t>(k)] = true;
    if (tab.units[static_cast<std::size_t>(k)].empty()) tab.units[static_cast<std::size_t>(k)] = c.value("unit", std::string());
  }
  for (std::size_t k = 0; k < described.size(); ++k)
    if (!described[k])
      throw InputError(meta + ": does not describe column '" + one_line(tab.names[k]) + "' of '" + tab.source +
                       "'; the two files are not from the same conversion");
}

DataTable read_csv_data(const std::string& path, const CsvOptions& options) {
  const nlohmann::json sidecar = sidecar_of(path);
  if (sidecar.is_null()) return read_csv(path, options);
  // A converted file's t is in seconds, whatever the scenario says of the raw file's time column.
  CsvOptions own = options;
  own.time_unit.clear();
  DataTable tab = read_csv(path, own);
  units_from_sidecar(tab, sidecar);
  return tab;
}

DataFileInfo describe_csv(const std::string& path, const CsvOptions& options) {
  const DataTable tab = read_csv_data(path, options);
  DataFileInfo info = describe_table(tab, "csv");
  info.notes.push_back("time column '" + tab.time_name + "'" + (tab.time_unit.empty() ? "" : " [" + tab.time_unit + "]"));
  return info;
}

// What a UFF specific data type measures ("" for the rest).
std::string quantity_of_spec(int spec) {
  switch (spec) {
    case 2: return "stress";
    case 3: return "strain";
    case 8: return "displacement";
    case 9: return "reaction force";
    case 11: return "velocity";
    case 12: return "acceleration";
    case 13: return "excitation force";
    case 15: return "pressure";
    case 17: return "time";
    case 18: return "frequency";
    default: return "";
  }
}

// A time response: function type 1, or a general function (0) whose abscissa is time.
bool is_time_response(const uff::Function& f) {
  return f.function_type == 1 || (f.function_type == 0 && f.abscissa.spec_type == 17);
}

std::string record_of(const uff::File& file, const uff::Function& f) {
  return "UFF file '" + file.source + "': record " + std::to_string(f.record) + " (dataset 58" + (f.binary ? "b" : "") +
         " at line " + std::to_string(f.line) + ", '" + one_line(uff::channel_name(f)) + "')";
}

// The abscissa of a function in seconds.
std::vector<double> seconds(const uff::File& file, const uff::Function& f) {
  std::vector<double> x = f.x;
  const std::string unit = uff::abscissa_unit(f);
  if (unit.empty() || unit == "s") return x;
  try {
    const units::Conversion c = units::conversion(unit, "s", units::Quantity::Time);
    for (double& v : x) v = c.apply(v);
  } catch (const std::invalid_argument& e) {
    throw InputError(record_of(file, f) + ": abscissa unit " + e.what());
  }
  return x;
}

// The time responses on their common time grid, one column each.
DataTable uff_table(const uff::File& file) {
  DataTable tab;
  tab.source = file.source;
  tab.time_unit = "s";
  const auto names = uff::channel_names(file);
  for (std::size_t i = 0; i < file.functions.size(); ++i) {
    const auto& f = file.functions[i];
    if (!is_time_response(f))
      throw InputError(record_of(file, f) + ": function type " + std::to_string(f.function_type) + " (" +
                       uff::function_type_name(f.function_type) +
                       ") is not a time response; only time responses (type 1) are data to identify from");
    if (f.is_complex()) throw InputError(record_of(file, f) + ": a time response with complex values (ordinate type " + std::to_string(f.ordinate_type) + ")");
    const std::vector<double> t = seconds(file, f);
    if (tab.names.empty()) {
      tab.t = t;
      for (std::size_t k = 1; k < t.size(); ++k)
        if (!(t[k] > t[k - 1]))
          throw InputError(record_of(file, f) + ": time must be strictly increasing, got " + format_value(t[k]) + " after " +
                           format_value(t[k - 1]) + " (point " + std::to_string(k + 1) + ")");
    } else {
      const double span = std::abs(tab.t.back() - tab.t.front());
      bool same = t.size() == tab.t.size();
      std::size_t differ = 0;
      for (std::size_t k = 0; k < std::min(t.size(), tab.t.size()); ++k)
        if (!(std::abs(t[k] - tab.t[k]) <= 1e-9 * span)) {
          same = false;
          differ = k;
          break;
        }
      auto grid = [](const std::vector<double>& g) {
        return std::to_string(g.size()) + " points from " + format_value(g.empty() ? 0.0 : g.front()) + " s" +
               (g.size() > 1 ? " every " + format_value((g.back() - g.front()) / static_cast<double>(g.size() - 1)) + " s" : "");
      };
      if (!same)
        throw InputError(record_of(file, f) + ": its time grid (" + grid(t) + ") differs from the first time response's (" +
                         grid(tab.t) + ")" +
                         (t.size() == tab.t.size() ? ": point " + std::to_string(differ + 1) + " is at " + format_value(t[differ]) +
                                                         " s against " + format_value(tab.t[differ]) + " s"
                                                   : "") +
                         "; the channels of one record share one time grid");
    }
    for (double v : f.re)
      if (!std::isfinite(v) || !(std::abs(v) <= limits::kMaxMagnitude))
        throw InputError(record_of(file, f) + ": values must be finite with magnitude at most " + format_value(limits::kMaxMagnitude) + ", got " + format_value(v));
    tab.names.push_back(names[i]);
    tab.units.push_back(uff::ordinate_unit(f));
    tab.columns.push_back(f.re);
  }
  if (tab.names.empty()) throw InputError("UFF file '" + file.source + "': no time response (dataset 58) to read");
  if (tab.t.size() < 2) throw InputError("UFF file '" + file.source + "': needs at least 2 samples, got " + std::to_string(tab.t.size()));
  return tab;
}

Channel uff_channel(const uff::Function& f, const std::string& name) {
  Channel c;
  c.name = name;
  c.unit = uff::ordinate_unit(f);
  c.quantity = quantity_of_spec(f.ordinate.spec_type);
  c.samples = f.re.size();
  c.start = f.x.empty() ? 0.0 : f.x.front();
  c.step = f.even ? f.abscissa_increment : (f.x.size() > 1 ? (f.x.back() - f.x.front()) / static_cast<double>(f.x.size() - 1) : 0.0);
  c.even = f.even;
  c.time_response = is_time_response(f);
  c.function = uff::function_type_name(f.function_type) + (f.is_complex() ? ", complex" : "");
  c.abscissa_unit = uff::abscissa_unit(f);
  c.record = static_cast<int>(f.record);
  c.node = f.response_node;
  c.direction = uff::direction_name(f.response_direction);
  return c;
}

std::vector<std::string> uff_notes(const uff::File& file) {
  std::vector<std::string> notes;
  if (file.header)
    notes.push_back("header (151): model '" + file.header->model_name + "', program '" + file.header->program + "', written " +
                    file.header->written);
  if (file.units) {
    const auto& u = *file.units;
    notes.push_back("units (164): code " + std::to_string(u.code) + " '" + u.description + "', factors length " +
                    format_value(u.length) + ", force " + format_value(u.force) + ", temperature " + format_value(u.temperature));
  }
  if (!file.nodes.empty()) notes.push_back("nodes (15/2411): " + std::to_string(file.nodes.size()));
  for (const auto& s : file.shapes) {
    std::string line = "shape (55) record " + std::to_string(s.record) + ": mode " + std::to_string(s.mode_number);
    if (std::isfinite(s.frequency_hz)) line += ", " + format_value(s.frequency_hz) + " Hz";
    if (std::isfinite(s.damping_ratio)) line += ", damping ratio " + format_value(s.damping_ratio);
    notes.push_back(line + ", " + std::to_string(s.nodes.size()) + " nodes x " + std::to_string(s.values_per_node) + " values");
  }
  for (const auto& k : file.skipped)
    notes.push_back("dataset " + std::to_string(k.dataset) + (k.binary ? "b" : "") + " (record " + std::to_string(k.record) +
                    ", line " + std::to_string(k.line) + "): not read");
  return notes;
}

DataFileInfo describe_uff(const std::string& path) {
  const uff::File file = uff::read_file(path);
  DataFileInfo info{path, "uff", {}, uff_notes(file)};
  const auto names = uff::channel_names(file);
  for (std::size_t i = 0; i < file.functions.size(); ++i) info.channels.push_back(uff_channel(file.functions[i], names[i]));
  return info;
}

}  // namespace

DataFileInfo describe_table(const DataTable& tab, const std::string& format) {
  DataFileInfo info{tab.source, format, {}, {}};
  const double n = static_cast<double>(tab.t.size());
  const double mean_step = (tab.t.back() - tab.t.front()) / (n - 1.0);
  // Evenly sampled when the times lie on a uniform grid within their written precision.
  const TimeGrid grid = uniform_grid(tab.t);
  const bool even = grid.uniform;
  if (grid.uniform && grid.precision != "full")
    info.notes.push_back("times written to " + grid.precision + ": a uniform clock of " + format_value(1.0 / grid.step) +
                         " Hz (largest rounding " + format_value(grid.max_shift) + " s)");
  else if (!grid.uniform)
    info.notes.push_back("times not uniform: sample " + std::to_string(grid.worst + 1) + " at " + format_value(tab.t[grid.worst]) +
                         " s lies " + format_value(grid.max_shift / grid.step) + " mean steps off the uniform grid");
  for (std::size_t j = 0; j < tab.names.size(); ++j) {
    Channel c;
    c.name = tab.names[j];
    c.unit = tab.unit(static_cast<int>(j));
    c.samples = tab.t.size();
    c.start = tab.t.front();
    c.step = mean_step;
    c.even = even;
    c.function = "time response";
    c.abscissa_unit = "s";
    info.channels.push_back(c);
  }
  return info;
}

bool is_lvm_file(const std::string& path) { return looks_like_lvm(file_head(path, 64)); }

namespace {
// Whether the file at `path` is a TDMS file (by its first 4 bytes, the lead-in tag "TDSm").
bool is_tdms_file(const std::string& path) { return looks_like_tdms(file_head(path, 4)); }
}  // namespace

bool is_csv_data(const std::string& path) { return !is_uff_file(path) && !is_lvm_file(path) && !is_tdms_file(path); }

CsvData open_csv_data(const std::string& path, const CsvOptions& options) {
  const nlohmann::json sidecar = sidecar_of(path);
  CsvOptions own = options;
  if (!sidecar.is_null()) own.time_unit.clear();  // a converted file's t is in seconds
  CsvData d;
  d.reader = std::make_unique<CsvReader>(path, own);
  DataTable head = d.reader->header();
  if (!sidecar.is_null()) units_from_sidecar(head, sidecar);
  head.units.resize(head.names.size());
  d.units = head.units;
  return d;
}

DataTable read_data(const std::string& path, const CsvOptions& options) {
  if (is_uff_file(path)) return uff_table(uff::read_file(path));
  if (is_lvm_file(path)) return read_lvm(path);
  if (is_tdms_file(path)) return read_tdms(path);
  return read_csv_data(path, options);
}

DataFileInfo describe_data(const std::string& path, const CsvOptions& options) {
  if (is_uff_file(path)) return describe_uff(path);
  if (is_lvm_file(path)) return describe_lvm(path);
  if (is_tdms_file(path)) return describe_tdms(path);
  return describe_csv(path, options);
}

}  // namespace scoleid::io
