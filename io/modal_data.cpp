#include "scoleid/io/modal_data.h"

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "scoleid/io/data_files.h"
#include "scoleid/io/error.h"
#include "scoleid/io/number.h"
#include "scoleid/io/input_file.h"
#include "scoleid/io/validation.h"

namespace scoleid::io {

bool ModalData::has_damping() const {
  if (modes.empty()) return false;
  for (const auto& m : modes)
    if (std::isnan(m.damping_ratio) || std::isnan(m.damping_std)) return false;
  return true;
}

namespace {

const char* const kMode = "mode";
const char* const kFrequency = "frequency_hz";
const char* const kFrequencyStd = "frequency_std_hz";
const char* const kDamping = "damping_ratio";
const char* const kDampingStd = "damping_std";
const char* const kShapeStd = "shape_std";

bool is_reserved(const std::string& name) {
  return name == kMode || name == kFrequency || name == kFrequencyStd || name == kDamping || name == kDampingStd ||
         name == kShapeStd;
}

bool blank(const std::string& line) { return line.find_first_not_of(" \t\r") == std::string::npos; }

struct Reader {
  std::string prefix;  // "modal data file '<source>'"

  [[noreturn]] void fail(std::size_t line, const std::string& what) const {
    throw InputError(one_line(prefix + ": line " + std::to_string(line) + ": " + what));
  }
  [[noreturn]] void fail(std::size_t line, const std::string& column, const std::string& what) const {
    throw InputError(one_line(prefix + ": line " + std::to_string(line) + ", column '" + column + "': " + what));
  }
};

// The requirements shared by the reader and validate_modal_data: `fail(column, requirement, value)`.
template <class Fail>
void check_value(const std::string& column, double v, const Fail& fail) {
  if (!std::isfinite(v)) fail(column, "must be finite", format_value(v));
  if (column == kFrequency && !(v > 0)) fail(column, "must be > 0", format_value(v));
  if ((column == kFrequencyStd || column == kDampingStd || column == kShapeStd) && !(v > 0))
    fail(column, "must be > 0 (a standard deviation)", format_value(v));
  if (column == kDamping && !(v >= 0)) fail(column, "must be >= 0", format_value(v));
}

}  // namespace

ModalData read_modal_data(const std::string& path) {
  return read_modal_data_text(read_text_file(path, "modal data file"), path);
}

ModalData read_modal_data_text(const std::string& text, const std::string& source) {
  ModalData d;
  d.source = source;
  const Reader rd{"modal data file '" + source + "'"};
  std::istringstream in(text);
  std::string line;
  std::size_t lineno = 0;
  bool have_header = false;
  while (std::getline(in, line)) {
    ++lineno;
    if (blank(line) || line[0] == '#') continue;
    have_header = true;
    break;
  }
  if (!have_header)
    throw InputError(one_line(rd.prefix + ": empty, expected a header line '" + kMode + "," + kFrequency + "," +
                              kFrequencyStd + "[," + kDamping + "," + kDampingStd + "][," + kShapeStd +
                              ",<station>,...]'"));
  const std::size_t header_line = lineno;
  check_utf8(line, rd.prefix + ": line " + std::to_string(lineno));
  const std::vector<std::string> header = split_csv_line(line);
  int i_mode = -1, i_f = -1, i_fs = -1, i_z = -1, i_zs = -1, i_ss = -1;
  std::vector<int> i_station;
  for (std::size_t j = 0; j < header.size(); ++j) {
    const std::string& h = header[j];
    if (h.empty()) rd.fail(header_line, "column " + std::to_string(j + 1) + " has an empty name");
    if (std::find(header.begin(), header.begin() + static_cast<std::ptrdiff_t>(j), h) !=
        header.begin() + static_cast<std::ptrdiff_t>(j))
      rd.fail(header_line, "duplicate column '" + h + "'");
    const int k = static_cast<int>(j);
    if (h == kMode)
      i_mode = k;
    else if (h == kFrequency)
      i_f = k;
    else if (h == kFrequencyStd)
      i_fs = k;
    else if (h == kDamping)
      i_z = k;
    else if (h == kDampingStd)
      i_zs = k;
    else if (h == kShapeStd)
      i_ss = k;
    else {
      i_station.push_back(k);
      d.stations.push_back(h);
    }
  }
  for (const auto& [idx, name] : {std::pair<int, const char*>{i_mode, kMode}, {i_f, kFrequency}, {i_fs, kFrequencyStd}})
    if (idx < 0)
      rd.fail(header_line, std::string("missing column '") + name + "' (the header needs " + kMode + ", " + kFrequency +
                               " and " + kFrequencyStd + "), got '" + line + "'");
  if ((i_z < 0) != (i_zs < 0))
    rd.fail(header_line, std::string("column '") + (i_z < 0 ? kDampingStd : kDamping) + "' needs column '" +
                             (i_z < 0 ? kDamping : kDampingStd) + "' as well (damping data come as both or neither)");
  if (!d.stations.empty() && i_ss < 0)
    rd.fail(header_line, "station columns ('" + d.stations.front() + "'" + (d.stations.size() > 1 ? ", ..." : "") +
                             ") need a '" + kShapeStd + "' column (standard deviation of the unit-normalised shape)");
  if (d.stations.empty() && i_ss >= 0)
    rd.fail(header_line, std::string("column '") + kShapeStd + "' without station columns");

  while (std::getline(in, line)) {
    ++lineno;
    if (blank(line) || line[0] == '#') continue;
    const std::vector<std::string> f = split_csv_line(line);
    if (f.size() != header.size())
      rd.fail(lineno,
              "expected " + std::to_string(header.size()) + " fields (one per header column" +
                  (d.stations.empty() ? std::string() : ", " + std::to_string(d.stations.size()) + " stations") +
                  "), got " + std::to_string(f.size()));
    ModalData::Mode m;
    m.shape.assign(d.stations.size(), 0.0);
    for (std::size_t j = 0; j < f.size(); ++j) {
      const std::string& col = header[j];
      const int k = static_cast<int>(j);
      if (k == i_mode) {
        errno = 0;
        char* end = nullptr;
        const long v = f[j].empty() ? 0 : std::strtol(f[j].c_str(), &end, 10);
        if (f[j].empty() || !end || *end != '\0' || errno == ERANGE || v <= 0 || v > INT_MAX)
          rd.fail(lineno, col, "must be a positive integer label, got '" + f[j] + "'");
        m.label = static_cast<int>(v);
        if (!d.modes.empty() && !(m.label > d.modes.back().label))
          rd.fail(lineno, col,
                  "labels must be strictly increasing, got " + f[j] + " after " + std::to_string(d.modes.back().label));
        continue;
      }
      double v = 0.0;
      bool ok = !f[j].empty();
      if (ok) {
        ok = parse_number(f[j], v);
      }
      if (!ok) rd.fail(lineno, col, "not a number, got '" + f[j] + "'");
      check_value(col, v, [&](const std::string& c, const std::string& req, const std::string&) {
        rd.fail(lineno, c, req + ", got " + f[j]);
      });
      if (k == i_f)
        m.frequency_hz = v;
      else if (k == i_fs)
        m.frequency_std_hz = v;
      else if (k == i_z)
        m.damping_ratio = v;
      else if (k == i_zs)
        m.damping_std = v;
      else if (k == i_ss)
        m.shape_std = v;
      else {
        const auto it = std::find(i_station.begin(), i_station.end(), k);
        m.shape[static_cast<std::size_t>(it - i_station.begin())] = v;
      }
    }
    d.modes.push_back(std::move(m));
  }
  if (d.modes.empty())
    throw InputError(
        one_line(rd.prefix + ": no modes (no data rows after the header on line " + std::to_string(header_line) + ")"));
  return d;
}

void validate_modal_data(const ModalData& d) {
  const std::string src = d.source.empty() ? std::string("modal data") : d.source;
  if (d.modes.empty()) fail_field(src, "modes", "must hold at least one mode", "none");
  for (std::size_t k = 0; k < d.stations.size(); ++k) {
    const std::string& s = d.stations[k];
    if (s.empty()) fail_field(src, "stations[" + std::to_string(k) + "]", "must be a non-empty name", "''");
    if (is_reserved(s))
      fail_field(src, "stations[" + std::to_string(k) + "]", "must not be a reserved column name", "'" + s + "'");
    if (std::find(d.stations.begin(), d.stations.begin() + static_cast<std::ptrdiff_t>(k), s) !=
        d.stations.begin() + static_cast<std::ptrdiff_t>(k))
      fail_field(src, "stations", "must be unique", "'" + one_line(s) + "' twice");
  }
  // Damping: all modes or none.
  bool any_damping = false;
  for (const auto& m : d.modes) any_damping = any_damping || !std::isnan(m.damping_ratio) || !std::isnan(m.damping_std);
  int previous = 0;
  for (const auto& m : d.modes) {
    const std::string f = "mode " + std::to_string(m.label);
    if (m.label <= 0) fail_field(src, f + ".mode", "must be a positive integer label", std::to_string(m.label));
    if (m.label <= previous)
      fail_field(src, f + ".mode", "labels must be strictly increasing",
                 std::to_string(m.label) + " after " + std::to_string(previous));
    previous = m.label;
    const auto fail = [&](const std::string& column, const std::string& req, const std::string& got) {
      fail_field(src, f + "." + column, req, got);
    };
    check_value(kFrequency, m.frequency_hz, fail);
    check_value(kFrequencyStd, m.frequency_std_hz, fail);
    if (any_damping) {
      check_value(kDamping, m.damping_ratio, fail);
      check_value(kDampingStd, m.damping_std, fail);
    }
    if (m.shape.size() != d.stations.size())
      fail_field(src, f + ".shape", "must hold one value per station (" + std::to_string(d.stations.size()) + ")",
                 std::to_string(m.shape.size()) + " values");
    if (!d.stations.empty()) {
      check_value(kShapeStd, m.shape_std, fail);
      for (std::size_t k = 0; k < m.shape.size(); ++k)
        if (!std::isfinite(m.shape[k])) fail(d.stations[k], "must be finite", format_value(m.shape[k]));
      if (std::all_of(m.shape.begin(), m.shape.end(), [](double v) { return v == 0.0; }))
        fail("shape", "must not vanish at every station", "0");
    }
  }
}

void write_modal_data(const std::string& path, const ModalData& d) {
  validate_modal_data(d);
  const bool damping = d.has_damping(), shapes = d.has_shapes();
  std::ostringstream os;
  os << kMode << ',' << kFrequency << ',' << kFrequencyStd;
  if (damping) os << ',' << kDamping << ',' << kDampingStd;
  if (shapes) {
    os << ',' << kShapeStd;
    for (const auto& s : d.stations) os << ',' << s;
  }
  os << '\n' << std::setprecision(17);
  for (const auto& m : d.modes) {
    os << m.label << ',' << m.frequency_hz << ',' << m.frequency_std_hz;
    if (damping) os << ',' << m.damping_ratio << ',' << m.damping_std;
    if (shapes) {
      os << ',' << m.shape_std;
      for (double v : m.shape) os << ',' << v;
    }
    os << '\n';
  }
  write_text_atomic(path, os.str());
}

}  // namespace scoleid::io
