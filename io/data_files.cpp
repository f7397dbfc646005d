#include "scoleid/io/data_files.h"

#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <set>
#include <stdexcept>
#include <sstream>
#include <type_traits>

#include "scoleid/io/error.h"
#include "scoleid/io/number.h"
#include "scoleid/io/signal.h"
#include "scoleid/io/input_file.h"
#include "scoleid/io/interrupt.h"
#include "scoleid/io/validation.h"

#include "scoleid/io/limits.h"
#include "scoleid/io/units.h"

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
  throw InputError(source + ": " + field + " " + requirement + ", got " + shorten(got));
}

int DataTable::find(const std::string& name) const {
  for (std::size_t j = 0; j < names.size(); ++j)
    if (names[j] == name) return static_cast<int>(j);
  return -1;
}

double DataTable::interpolate(int j, double tt) const {
  return linear_table_value(t, columns.at(static_cast<std::size_t>(j)), tt);
}

std::string DataTable::unit(int j) const {
  return j >= 0 && static_cast<std::size_t>(j) < units.size() ? units[static_cast<std::size_t>(j)] : std::string();
}

namespace {

std::string trim_field(const std::string& s, const char* chars) {
  const auto b = s.find_first_not_of(chars);
  const auto e = s.find_last_not_of(chars);
  return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
}

}  // namespace

std::vector<std::string> split_csv_line(const std::string& line, char separator) {
  std::vector<std::string> out;
  std::string cur;
  bool quoted = false, was_quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (c == '"') {
      if (quoted && i + 1 < line.size() && line[i + 1] == '"') {
        cur.push_back('"');
        ++i;
      } else {
        // Blanks before an opening quote are outside the field ("t, \"a\"" names a).
        if (!quoted && !was_quoted && cur.find_first_not_of(" \t") == std::string::npos) cur.clear();
        quoted = !quoted;
        was_quoted = true;
      }
    } else if (c == separator && !quoted) {
      out.push_back(was_quoted ? cur : trim_field(cur, " \t\""));
      cur.clear();
      was_quoted = false;
    } else if (c != '\r' && (quoted || !was_quoted || (c != ' ' && c != '\t'))) {
      cur.push_back(c);  // (blanks after a closing quote are outside the field too)
    }
  }
  out.push_back(was_quoted ? cur : trim_field(cur, " \t\""));
  return out;
}

DataTable read_csv(const std::string& path, const CsvOptions& options) {
  InputFileStream in(path, "data file '" + path + "'");
  return read_csv_stream(in, path, options);
}

DataTable read_csv_text(const std::string& text, const std::string& path, const CsvOptions& options) {
  std::istringstream in(text);
  return read_csv_stream(in, path, options);
}

namespace {

// The separator a header line uses: ';' or a tab where it has one outside quotes, else ','.
char separator_of(const std::string& header) {
  bool quoted = false, semicolon = false, tab = false;
  for (char c : header) {
    if (c == '"') quoted = !quoted;
    if (quoted) continue;
    semicolon = semicolon || c == ';';
    tab = tab || c == '\t';
  }
  return semicolon ? ';' : tab ? '\t' : ',';
}

// The header line (after '#' comments, blank lines and a byte-order mark); lineno counts lines.
std::string header_line(std::istream& in, const std::string& path, std::size_t& lineno) {
  std::string line;
  while (std::getline(in, line)) {
    ++lineno;
    // A UTF-8 byte-order mark (spreadsheets write one) belongs to no line's content.
    if (lineno == 1 && line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);
    if (!line.empty() && line[0] == '#') continue;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    break;
  }
  if (lineno == 0 || line.find_first_not_of(" \t\r") == std::string::npos) {
    check_interrupt();  // a read interrupted by a signal ends like an empty file
    throw InputError("data file '" + path + "': empty, expected a header line (time column first)");
  }
  // Lines ended by CR alone (classic Mac) arrive as one line: say so rather than misread it. A CR
  // followed by anything but another CR is inside the line (CR CR LF endings are read as before).
  for (std::size_t i = 0; i + 1 < line.size(); ++i)
    if (line[i] == '\r' && line[i + 1] != '\r')
      throw InputError("data file '" + path + "': line " + std::to_string(lineno) +
                       ": lines end in CR alone; save the file with LF or CR LF line endings");
  check_utf8(line, "data file '" + path + "': line " + std::to_string(lineno));
  return line;
}

// The time column's index and the table's names and units from the header.
std::size_t read_header(const std::vector<std::string>& header, const CsvOptions& options, DataTable& tab,
                        const std::string& where) {
  std::size_t time = 0;
  if (!options.time_column.empty()) {
    const auto it = std::find(header.begin(), header.end(), options.time_column);
    if (it == header.end())
      throw InputError(where + ": no time column '" + one_line(options.time_column) + "' (data.time_column); the header's first is '" +
                       one_line(header[0]) + "'");
    time = static_cast<std::size_t>(it - header.begin());
  }
  if (header.size() < 2) throw InputError(where + ": no data columns beside the time column '" + one_line(header[time]) + "'");
  std::set<std::string> seen;
  for (std::size_t j = 0; j < header.size(); ++j) {
    if (header[j].empty())
      throw InputError(where + ": column " + std::to_string(j + 1) + " has an empty name");
    if (!seen.insert(header[j]).second) throw InputError(where + ": duplicate column '" + one_line(header[j]) + "'");
    if (j == time) continue;
    tab.names.push_back(header[j]);
    tab.units.push_back(units::bracketed_unit(header[j]));
  }
  tab.time_name = header[time];
  tab.time_unit = units::bracketed_unit(header[time]);
  if (tab.time_unit.empty()) tab.time_unit = options.time_unit;
  return time;
}

// t into seconds from the time column's unit.
void time_in_seconds(DataTable& tab, const std::string& where) {
  if (tab.time_unit.empty() || tab.time_unit == "s") return;
  units::Conversion c;
  try {
    c = units::conversion(tab.time_unit, "s", units::Quantity::Time);
  } catch (const std::invalid_argument& e) {
    throw InputError(where + ": time column '" + one_line(tab.time_name) + "': unit " + e.what());
  }
  for (double& x : tab.t) x = c.apply(x);
  for (std::size_t k = 1; k < tab.t.size(); ++k)
    if (!(tab.t[k] > tab.t[k - 1]))
      throw InputError(where + ": time column '" + one_line(tab.time_name) + "': sample " + std::to_string(k + 1) +
                       " is not after the one before once converted from " + tab.time_unit + " into s (" + format_value(tab.t[k]) + ")");
}

}  // namespace

struct CsvReader::State {
  std::unique_ptr<InputFileStream> own;  // the file, when the reader opened it
  std::istream* in = nullptr;
  DataTable head;
  std::string path, line, number;
  std::size_t lineno = 0, rows = 0, time = 0, fields = 0;
  char sep = ',';
  bool decimal_comma = false, trailing = false;
  std::vector<std::string> header;
  std::vector<std::string_view> view;  // the fields of the line being read
  std::vector<std::string> quoted;     // their text when the line has quotes
  double last_raw = 0, last_s = 0;     // the time before, in its stated unit and in seconds
  bool to_seconds = false;
  units::Conversion seconds;

  std::string where() const { return "data file '" + path + "': line " + std::to_string(lineno); }
  std::string where(std::size_t j) const { return where() + ", column '" + one_line(header[j]) + "'"; }

  void start(const CsvOptions& options) {
    head.source = path;
    line = header_line(*in, path, lineno);
    sep = separator_of(line);
    decimal_comma = sep != ',';
    header = split_csv_line(line, sep);
    // Exports that end every line with the separator ("t;a;b;") have an empty last field throughout.
    trailing = header.size() > 2 && header.back().empty();
    if (trailing) header.pop_back();
    time = read_header(header, options, head, where());
    fields = header.size();
    if (!head.time_unit.empty() && head.time_unit != "s") {
      try {
        seconds = units::conversion(head.time_unit, "s", units::Quantity::Time);
      } catch (const std::invalid_argument& e) {
        throw InputError("data file '" + path + "': time column '" + one_line(head.time_name) + "': unit " + e.what());
      }
      to_seconds = true;
    }
  }

  // The current line's fields into view (false: a blank or comment line).
  bool split() {
    if (line.find_first_not_of(" \t\r") == std::string::npos || line[0] == '#') return false;
    view.clear();
    if (line.find('"') != std::string::npos) {  // quoted fields: the general splitter
      quoted = split_csv_line(line, sep);
      for (const auto& f : quoted) view.emplace_back(f);
    } else {
      std::size_t b = 0;
      for (;;) {
        const std::size_t e = line.find(sep, b);
        std::string_view f(line.data() + b, (e == std::string::npos ? line.size() : e) - b);
        const auto l = f.find_first_not_of(" \t\r"), r = f.find_last_not_of(" \t\r");
        view.push_back(l == std::string_view::npos ? std::string_view() : f.substr(l, r - l + 1));
        if (e == std::string::npos) break;
        b = e + 1;
      }
    }
    if (trailing && view.size() == fields + 1 && view.back().empty()) view.pop_back();
    if (view.size() != fields)
      throw InputError(where() + ": expected " + std::to_string(fields) + " fields, got " + std::to_string(view.size()));
    return true;
  }

  double value(std::size_t j) {
    std::string_view f = view[j];
    if (decimal_comma && f.find(',') != std::string_view::npos) {
      number.assign(f);
      std::replace(number.begin(), number.end(), ',', '.');
      f = number;
    }
    double v = 0.0;
    if (f.empty() || !parse_number(f, v)) throw InputError(where(j) + ": not a number, got '" + one_line(std::string(view[j])) + "'");
    if (!std::isfinite(v)) throw InputError(where(j) + ": must be finite, got " + std::string(view[j]));
    if (!(std::abs(v) <= limits::kMaxMagnitude))  // (tiny values are data; huge ones overflow the fit)
      throw InputError(where(j) + ": magnitude must be at most " + format_value(limits::kMaxMagnitude) + ", got " + format_value(v));
    return v;
  }
};

CsvReader::CsvReader(const std::string& path, const CsvOptions& options) : s_(std::make_unique<State>()) {
  s_->own = std::make_unique<InputFileStream>(path, "data file '" + path + "'");
  s_->in = s_->own.get();
  s_->path = path;
  s_->start(options);
}

CsvReader::CsvReader(std::istream& in, const std::string& path, const CsvOptions& options) : s_(std::make_unique<State>()) {
  s_->in = &in;
  s_->path = path;
  s_->start(options);
}

CsvReader::~CsvReader() = default;

const DataTable& CsvReader::header() const { return s_->head; }
std::size_t CsvReader::rows() const { return s_->rows; }

std::size_t CsvReader::read(std::size_t max_rows, std::vector<double>& t, std::vector<std::vector<double>>& columns,
                            double max_samples) {
  State& s = *s_;
  t.clear();
  columns.resize(s.head.names.size());
  for (auto& c : columns) c.clear();
  while (t.size() < max_rows && std::getline(*s.in, s.line)) {
    ++s.lineno;
    if (s.lineno % 4096 == 0) check_interrupt();  // a DAQ export of millions of lines takes seconds
    if (!s.split()) continue;
    if (max_samples > 0 && static_cast<double>(s.rows) >= max_samples)
      throw InputError(s.where() + ": more than " + format_value(max_samples) + " samples (the limit of one record)");
    for (std::size_t j = 0; j < s.fields; ++j) {
      const double v = s.value(j);
      if (j != s.time) {
        columns[j < s.time ? j : j - 1].push_back(v);
        continue;
      }
      if (s.rows > 0 && !(v > s.last_raw))
        throw InputError(s.where(j) + ": time must be strictly increasing, got " + std::string(s.view[j]) + " after " +
                         format_value(s.last_raw));
      const double sec = s.to_seconds ? s.seconds.apply(v) : v;
      if (s.rows > 0 && !(sec > s.last_s))
        throw InputError("data file '" + s.path + "': time column '" + one_line(s.head.time_name) + "': sample " +
                         std::to_string(s.rows + 1) + " is not after the one before once converted from " + s.head.time_unit +
                         " into s (" + format_value(sec) + ")");
      s.last_raw = v;
      s.last_s = sec;
      t.push_back(sec);
    }
    ++s.rows;
  }
  check_interrupt();  // a read cut short by a signal is no short file
  return t.size();
}

DataTable read_csv_stream(std::istream& in, const std::string& path, const CsvOptions& options) {
  CsvReader reader(in, path, options);
  DataTable tab = reader.header();
  tab.columns.assign(tab.names.size(), {});
  std::vector<double> t;
  std::vector<std::vector<double>> cols;
  while (reader.read(std::size_t{1} << 16, t, cols, limits::kMaxSamples) > 0) {
    tab.t.insert(tab.t.end(), t.begin(), t.end());
    for (std::size_t j = 0; j < cols.size(); ++j) tab.columns[j].insert(tab.columns[j].end(), cols[j].begin(), cols[j].end());
  }
  if (tab.t.size() < 2)
    throw InputError("data file '" + path + "': needs at least 2 data rows, got " + std::to_string(tab.t.size()));
  return tab;
}

DataTable table_from_columns(const std::vector<std::string>& header, const std::vector<std::vector<double>>& columns,
                             const std::string& source, const CsvOptions& options) {
  if (header.size() != columns.size())
    throw std::logic_error("table_from_columns: " + std::to_string(header.size()) + " names for " + std::to_string(columns.size()) + " columns");
  DataTable tab;
  tab.source = source;
  if (header.empty()) throw InputError("data '" + one_line(shorten(source)) + "': no columns");
  const std::size_t time = read_header(header, options, tab, "data '" + one_line(shorten(source)) + "'");
  tab.t = columns[time];
  for (std::size_t j = 0; j < columns.size(); ++j)
    if (j != time) tab.columns.push_back(columns[j]);
  check_table(tab);  // finite and increasing in the unit stated, then converted as a file's
  time_in_seconds(tab, "data '" + one_line(shorten(source)) + "'");
  return tab;
}

void check_table(const DataTable& tab) {
  const std::string src = "data '" + one_line(shorten(tab.source)) + "'";
  const std::size_t n = tab.t.size();
  if (n < 2) throw InputError(src + ": needs at least 2 samples, got " + std::to_string(n));
  if (n > static_cast<std::size_t>(limits::kMaxSamples))
    throw InputError(src + ": " + std::to_string(n) + " samples, more than " + format_value(limits::kMaxSamples) +
                     " (the limit of one record)");
  if (tab.columns.size() != tab.names.size())
    throw InputError(src + ": " + std::to_string(tab.names.size()) + " column names for " + std::to_string(tab.columns.size()) +
                     " columns");
  if (tab.names.empty()) throw InputError(src + ": no data columns beside the time");
  std::set<std::string> seen;
  for (const auto& name : tab.names) {
    if (name.empty()) throw InputError(src + ": a column has an empty name");
    if (name == tab.time_name || name == "t")
      throw InputError(src + ": column '" + one_line(shorten(name)) + "' has the time column's name");
    if (!seen.insert(name).second) throw InputError(src + ": duplicate column '" + one_line(shorten(name)) + "'");
  }
  auto bad = [&](const std::string& col, std::size_t k, const std::string& what, double v) {
    throw InputError(src + ": " + col + ", sample " + std::to_string(k + 1) + (col == "time" ? "" : " (t = " + format_value(tab.t[k]) + " s)") +
                     ": " + what + ", got " + format_value(v));
  };
  for (std::size_t k = 0; k < n; ++k) {
    const double v = tab.t[k];
    if (!std::isfinite(v)) bad("time", k, "must be finite", v);
    if (!(std::abs(v) <= limits::kMaxMagnitude)) bad("time", k, "magnitude must be at most " + format_value(limits::kMaxMagnitude), v);
    if (k > 0 && !(v > tab.t[k - 1]))
      bad("time", k, "must be strictly increasing (after " + format_value(tab.t[k - 1]) + ")", v);
  }
  for (std::size_t j = 0; j < tab.names.size(); ++j) {
    const std::string col = "column '" + one_line(shorten(tab.names[j])) + "'";
    if (tab.columns[j].size() != n)
      throw InputError(src + ": " + col + " has " + std::to_string(tab.columns[j].size()) + " values for " + std::to_string(n) + " times");
    for (std::size_t k = 0; k < n; ++k) {
      const double v = tab.columns[j][k];
      if (!std::isfinite(v)) bad(col, k, "must be finite", v);
      if (!(std::abs(v) <= limits::kMaxMagnitude)) bad(col, k, "magnitude must be at most " + format_value(limits::kMaxMagnitude), v);
    }
  }
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

// A header field as CSV writes it: quoted when it holds a separator, a quote or outer blanks.
std::string csv_field(const std::string& name) {
  const bool plain = name.find_first_of(",;\"\t") == std::string::npos && !name.empty() && name.front() != ' ' &&
                     name.back() != ' ' && name.front() != '#';
  if (plain) return name;
  std::string q = "\"";
  for (char c : name) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

void write_csv(const std::string& path, const DataTable& tab) {
  std::string out = csv_field(tab.time_name.empty() ? std::string("t") : tab.time_name);
  for (const auto& n : tab.names) out += ',' + csv_field(n);
  out += '\n';
  // Each value in its shortest form that reads back to the same double (std::to_chars).
  char buf[32];
  auto put = [&](double v) {
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    out.append(buf, r.ptr);
  };
  out.reserve(out.size() + tab.t.size() * (tab.columns.size() + 1) * 24);
  for (std::size_t i = 0; i < tab.t.size(); ++i) {
    if (i % 4096 == 0) check_interrupt();
    put(tab.t[i]);
    for (const auto& c : tab.columns) {
      out += ',';
      put(c[i]);
    }
    out += '\n';
  }
  write_text_atomic(path, out);
}

void write_json_atomic(const std::string& path, const nlohmann::json& j) {
  // Every string the programs put in JSON is validated UTF-8; the replacement handler is the last
  // line of defence, so a stray byte can never abort a run at its end.
  write_text_atomic(path, j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
}

nlohmann::json read_json(const std::string& path) {
  return parse_json_text(read_text_file(path, "JSON file"), "JSON file '" + path + "'");
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

namespace {

const char* json_kind(const nlohmann::json& v) {
  return v.is_null() ? "null" : v.is_boolean() ? "a boolean" : v.is_number() ? "a number" : v.is_string() ? "text"
         : v.is_array() ? "a list" : "an object";
}

// The member `key` of object `o` as T, or `dflt` when absent; InputError naming the field otherwise.
template <class T>
T member(const nlohmann::json& o, const char* key, const T& dflt, const std::string& source, const std::string& field) {
  const auto it = o.find(key);
  if (it == o.end()) return dflt;
  try {
    return it->get<T>();
  } catch (const nlohmann::json::exception&) {
    fail_field(source, field + key, std::is_same<T, std::string>::value ? "must be text" : "must be a number (or a list of numbers)",
               json_kind(*it));
  }
}

ColumnMeta column_meta(const nlohmann::json& c, std::size_t i, const std::string& source) {
  const std::string at = "columns[" + std::to_string(i) + "].";
  if (!c.is_object()) fail_field(source, "columns[" + std::to_string(i) + "]", "must be an object", json_kind(c));
  if (!c.contains("name")) fail_field(source, at + "name", "is required", "none");
  ColumnMeta cm;
  cm.name = member<std::string>(c, "name", "", source, at);
  const std::string f = "columns['" + one_line(cm.name) + "'].";
  cm.unit = member<std::string>(c, "unit", "", source, f);
  cm.kind = member<std::string>(c, "kind", "", source, f);
  if (cm.kind != "input" && cm.kind != "output") fail_field(source, f + "kind", "must be input or output", "'" + cm.kind + "'");
  cm.quantity = member<std::string>(c, "quantity", "", source, f);
  cm.at = member<std::string>(c, "at", "", source, f);
  cm.location = member<double>(c, "location", 0.0, source, f);
  cm.direction = member<std::vector<double>>(c, "direction", {0, 0, 0}, source, f);
  cm.noise_std = member<double>(c, "noise_std", 0.0, source, f);
  if (!std::isfinite(cm.noise_std) || cm.noise_std < 0 || cm.noise_std > limits::kMaxMagnitude)
    fail_field(source, f + "noise_std", "must be a number in [0, " + format_value(limits::kMaxMagnitude) + "]", format_value(cm.noise_std));
  if (!std::isfinite(cm.location)) fail_field(source, f + "location", "must be finite", format_value(cm.location));
  for (double d : cm.direction)
    if (!std::isfinite(d)) fail_field(source, f + "direction", "must be finite", format_value(d));
  return cm;
}

}  // namespace

TruthMeta truth_meta_from_json(const nlohmann::json& j, const std::string& source) {
  TruthMeta m;
  if (!j.is_object()) fail_field(source, "document", "must be a JSON object", json_kind(j));
  m.scenario = member<std::string>(j, "scenario", "", source, "");
  m.structure = member<std::string>(j, "structure", "", source, "");
  if (j.contains("columns")) {
    const auto& cols = j.at("columns");
    if (!cols.is_array()) fail_field(source, "columns", "must be a list", json_kind(cols));
    for (std::size_t i = 0; i < cols.size(); ++i) {
      ColumnMeta cm = column_meta(cols[i], i, source);
      for (const auto& other : m.columns)
        if (other.name == cm.name) fail_field(source, "columns['" + one_line(cm.name) + "']", "must appear once", "a second column of that name");
      m.columns.push_back(std::move(cm));
    }
  }
  if (j.contains("true_parameters")) {
    const auto& tp = j.at("true_parameters");
    if (!tp.is_object()) fail_field(source, "true_parameters", "must be an object {name: value}", json_kind(tp));
    for (const auto& [k, v] : tp.items()) {
      if (!v.is_number()) fail_field(source, "true_parameters." + one_line(k), "must be a number", json_kind(v));
      const double x = v.get<double>();
      if (!std::isfinite(x) || !(x >= 0)) fail_field(source, "true_parameters." + one_line(k), "must be a finite number >= 0", format_value(x));
      // The range every number of a scenario has (limits.h): a true value beyond it is no truth.
      if (x != 0 && !(x >= limits::kMinMagnitude && x <= limits::kMaxMagnitude))
        fail_field(source, "true_parameters." + one_line(k),
                   "must be 0 or of magnitude within [" + format_value(limits::kMinMagnitude) + ", " +
                       format_value(limits::kMaxMagnitude) + "], as every number of a scenario",
                   format_value(x));
      m.true_parameters[k] = x;
    }
  }
  if (j.contains("generator")) m.generator = j.at("generator");
  if (j.contains("settings")) m.settings = j.at("settings");
  return m;
}

TruthMeta read_truth_meta(const std::string& path) { return truth_meta_from_json(read_json(path), path); }

}  // namespace scoleid::io
