#include "scoleid/io/data_files.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "scoleid/io/error.h"
#include "scoleid/io/validation.h"

#include "scoleid/io/limits.h"

namespace scoleid::io {

std::string format_value(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  std::ostringstream os;
  os << std::setprecision(15) << v;
  return os.str();
}

void fail_field(const std::string& source, const std::string& field, const std::string& requirement,
                const std::string& got) {
  throw InputError(source + ": " + field + " " + requirement + ", got " + got);
}

int DataTable::find(const std::string& name) const {
  for (std::size_t j = 0; j < names.size(); ++j)
    if (names[j] == name) return static_cast<int>(j);
  return -1;
}

double DataTable::interpolate(int j, double tt) const {
  const auto& v = columns.at(static_cast<std::size_t>(j));
  if (t.empty()) return 0.0;
  if (tt <= t.front()) return v.front();
  if (tt >= t.back()) return v.back();
  const auto it = std::upper_bound(t.begin(), t.end(), tt);
  const std::size_t k = static_cast<std::size_t>(it - t.begin());
  const double a = (tt - t[k - 1]) / (t[k] - t[k - 1]);
  return (1.0 - a) * v[k - 1] + a * v[k];
}

std::vector<std::string> split_csv_line(const std::string& line) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : line) {
    if (c == ',') {
      out.push_back(cur);
      cur.clear();
    } else if (c != '\r') {
      cur.push_back(c);
    }
  }
  out.push_back(cur);
  for (auto& s : out) {
    const auto b = s.find_first_not_of(" \t\"");
    const auto e = s.find_last_not_of(" \t\"");
    s = (b == std::string::npos) ? std::string() : s.substr(b, e - b + 1);
  }
  return out;
}

DataTable read_csv(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw InputError("data file '" + path + "': is a directory");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError("data file '" + path + "': cannot be opened");
  return read_csv_stream(in, path);
}

DataTable read_csv_text(const std::string& text, const std::string& path) {
  std::istringstream in(text);
  return read_csv_stream(in, path);
}

DataTable read_csv_stream(std::istream& in, const std::string& path) {
  DataTable tab;
  tab.source = path;
  std::string line;
  std::size_t lineno = 0;
  // Header (skipping '#' comment lines).
  while (std::getline(in, line)) {
    ++lineno;
    // A UTF-8 byte-order mark (spreadsheets write one) belongs to no line's content.
    if (lineno == 1 && line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);
    if (!line.empty() && line[0] == '#') continue;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    break;
  }
  if (lineno == 0 || line.find_first_not_of(" \t\r") == std::string::npos)
    throw InputError("data file '" + path + "': empty, expected a header line starting with 't'");
  // Lines ended by CR alone (classic Mac) arrive as one line: say so rather than misread it. A CR
  // followed by anything but another CR is inside the line (CR CR LF endings are read as before).
  for (std::size_t i = 0; i + 1 < line.size(); ++i)
    if (line[i] == '\r' && line[i + 1] != '\r')
      throw InputError("data file '" + path + "': line " + std::to_string(lineno) +
                       ": lines end in CR alone; save the file with LF or CR LF line endings");
  check_utf8(line, "data file '" + path + "': line " + std::to_string(lineno));
  const auto header = split_csv_line(line);
  if (header.empty() || header[0] != "t")
    throw InputError("data file '" + path + "': line " + std::to_string(lineno) +
                     ": first column must be 't', got '" + (header.empty() ? "" : header[0]) + "'");
  if (header.size() < 2)
    throw InputError("data file '" + path + "': line " + std::to_string(lineno) + ": no data columns after 't'");
  for (std::size_t j = 1; j < header.size(); ++j) {
    if (header[j].empty())
      throw InputError("data file '" + path + "': line " + std::to_string(lineno) + ": column " +
                       std::to_string(j + 1) + " has an empty name");
    if (std::find(tab.names.begin(), tab.names.end(), header[j]) != tab.names.end())
      throw InputError("data file '" + path + "': line " + std::to_string(lineno) + ": duplicate column '" +
                       header[j] + "'");
    tab.names.push_back(header[j]);
  }
  tab.columns.assign(tab.names.size(), {});
  while (std::getline(in, line)) {
    ++lineno;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    if (line[0] == '#') continue;
    const auto f = split_csv_line(line);
    if (f.size() != header.size())
      throw InputError("data file '" + path + "': line " + std::to_string(lineno) + ": expected " +
                       std::to_string(header.size()) + " fields, got " + std::to_string(f.size()));
    for (std::size_t j = 0; j < f.size(); ++j) {
      double v = 0.0;
      bool ok = !f[j].empty();
      if (ok) {
        char* end = nullptr;
        v = std::strtod(f[j].c_str(), &end);
        ok = end && *end == '\0';
      }
      if (!ok)
        throw InputError("data file '" + path + "': line " + std::to_string(lineno) + ", column '" + header[j] +
                         "': not a number, got '" + f[j] + "'");
      if (!std::isfinite(v))
        throw InputError("data file '" + path + "': line " + std::to_string(lineno) + ", column '" + header[j] +
                         "': must be finite, got " + f[j]);
      if (!(std::abs(v) <= limits::kMaxMagnitude))  // (tiny values are data; huge ones overflow the fit)
        throw InputError("data file '" + path + "': line " + std::to_string(lineno) + ", column '" + header[j] +
                         "': magnitude must be at most " + format_value(limits::kMaxMagnitude) + ", got " + format_value(v));
      if (j == 0) {
        if (!tab.t.empty() && !(v > tab.t.back()))
          throw InputError("data file '" + path + "': line " + std::to_string(lineno) +
                           ", column 't': time must be strictly increasing, got " + f[j] + " after " +
                           format_value(tab.t.back()));
        tab.t.push_back(v);
      } else {
        tab.columns[j - 1].push_back(v);
      }
    }
  }
  if (tab.t.size() < 2)
    throw InputError("data file '" + path + "': needs at least 2 data rows, got " + std::to_string(tab.t.size()));
  return tab;
}

void write_text_atomic(const std::string& path, const std::string& text) {
  namespace fs = std::filesystem;
  const fs::path target(path);
  const fs::path tmp = target.parent_path() / (target.filename().string() + ".tmp." + std::to_string(::getpid()));
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw std::runtime_error("cannot write '" + tmp.string() + "'");
    out << text;
    out.flush();
    if (!out) {
      out.close();
      std::error_code ec;
      fs::remove(tmp, ec);
      throw std::runtime_error("write failed for '" + tmp.string() + "'");
    }
  }
  std::error_code ec;
  fs::rename(tmp, target, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw std::runtime_error("cannot rename into '" + path + "'");
  }
}

void write_csv(const std::string& path, const DataTable& tab) {
  std::ostringstream os;
  os << "t";
  for (const auto& n : tab.names) os << ',' << n;
  os << '\n' << std::setprecision(17);
  for (std::size_t i = 0; i < tab.t.size(); ++i) {
    os << tab.t[i];
    for (const auto& c : tab.columns) os << ',' << c[i];
    os << '\n';
  }
  write_text_atomic(path, os.str());
}

void write_json_atomic(const std::string& path, const nlohmann::json& j) {
  // Every string the programs put in JSON is validated UTF-8; the replacement handler is the last
  // line of defence, so a stray byte can never abort a run at its end.
  write_text_atomic(path, j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
}

nlohmann::json read_json(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw InputError("JSON file '" + path + "': is a directory");
  std::ifstream in(path);
  if (!in) throw InputError("JSON file '" + path + "': cannot be opened");
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::parse_error& e) {
    throw InputError("JSON file '" + path + "': malformed at byte " + std::to_string(e.byte));
  }
}

void ensure_directory(const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir))
    throw InputError("output directory '" + dir + "': cannot be created (" + ec.message() + ")");
}

nlohmann::json to_json(const TruthMeta& m) {
  nlohmann::json cols = nlohmann::json::array();
  for (const auto& c : m.columns)
    cols.push_back({{"name", c.name}, {"unit", c.unit}, {"kind", c.kind}, {"quantity", c.quantity},
                    {"at", c.at}, {"location", c.location}, {"direction", c.direction},
                    {"noise_std", c.noise_std}});
  return {{"scenario", m.scenario}, {"structure", m.structure}, {"columns", cols},
          {"true_parameters", m.true_parameters}, {"generator", m.generator}, {"settings", m.settings}};
}

TruthMeta truth_meta_from_json(const nlohmann::json& j, const std::string& source) {
  TruthMeta m;
  try {
    m.scenario = j.value("scenario", "");
    m.structure = j.value("structure", "");
    if (j.contains("columns")) {
      for (const auto& c : j.at("columns")) {
        ColumnMeta cm;
        cm.name = c.at("name").get<std::string>();
        cm.unit = c.value("unit", "");
        cm.kind = c.value("kind", "");
        if (cm.kind != "input" && cm.kind != "output")
          fail_field(source, "columns['" + cm.name + "'].kind", "must be input or output", "'" + cm.kind + "'");
        cm.quantity = c.value("quantity", "");
        cm.at = c.value("at", "");
        cm.location = c.value("location", 0.0);
        cm.direction = c.value("direction", std::vector<double>{0, 0, 0});
        cm.noise_std = c.value("noise_std", 0.0);
        const std::string f = "columns['" + one_line(cm.name) + "']";
        for (const auto& other : m.columns)
          if (other.name == cm.name) fail_field(source, f, "must appear once", "a second column of that name");
        if (!std::isfinite(cm.noise_std) || cm.noise_std < 0 || cm.noise_std > limits::kMaxMagnitude)
          fail_field(source, f + ".noise_std", "must be a number in [0, " + format_value(limits::kMaxMagnitude) + "]",
                     format_value(cm.noise_std));
        if (!std::isfinite(cm.location)) fail_field(source, f + ".location", "must be finite", format_value(cm.location));
        for (double d : cm.direction)
          if (!std::isfinite(d)) fail_field(source, f + ".direction", "must be finite", format_value(d));
        m.columns.push_back(cm);
      }
    }
    if (j.contains("true_parameters")) {
      m.true_parameters = j.at("true_parameters").get<std::map<std::string, double>>();
      for (const auto& [k, v] : m.true_parameters)
        if (!std::isfinite(v) || !(v >= 0))
          fail_field(source, "true_parameters." + one_line(k), "must be a finite number >= 0", format_value(v));
    }
    if (j.contains("generator")) m.generator = j.at("generator");
    if (j.contains("settings")) m.settings = j.at("settings");
  } catch (const nlohmann::json::exception& e) {
    throw InputError(source + ": unexpected structure (" + std::string(e.what()) + ")");
  }
  return m;
}

TruthMeta read_truth_meta(const std::string& path) { return truth_meta_from_json(read_json(path), path); }

}  // namespace scoleid::io
