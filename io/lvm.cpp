#include "scoleid/io/lvm.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string_view>

#include "scoleid/io/error.h"
#include "scoleid/io/input_file.h"
#include "scoleid/io/interrupt.h"
#include "scoleid/io/limits.h"
#include "scoleid/io/number.h"
#include "scoleid/io/validation.h"

namespace scoleid::io {

namespace {

constexpr const char* kMagic = "LabVIEW Measurement";
constexpr const char* kEnd = "***End_of_Header***";

std::vector<std::string> split(const std::string& line, char sep) {
  std::vector<std::string> f;
  std::size_t b = 0;
  for (;;) {
    const std::size_t e = line.find(sep, b);
    f.push_back(line.substr(b, e == std::string::npos ? std::string::npos : e - b));
    if (e == std::string::npos) break;
    b = e + 1;
  }
  return f;
}

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r"), e = s.find_last_not_of(" \t\r");
  return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
}

// The data rows' fields as views into the row (no copy per cell: a record has millions of them).
std::string_view trim_view(std::string_view s) {
  const auto b = s.find_first_not_of(" \t\r"), e = s.find_last_not_of(" \t\r");
  return b == std::string_view::npos ? std::string_view() : s.substr(b, e - b + 1);
}

void split_view(std::string_view line, char sep, std::vector<std::string_view>& f) {
  f.clear();
  std::size_t b = 0;
  for (;;) {
    const std::size_t e = line.find(sep, b);
    f.push_back(line.substr(b, e == std::string_view::npos ? std::string_view::npos : e - b));
    if (e == std::string_view::npos) break;
    b = e + 1;
  }
}


struct Lvm {
  std::string path;
  char sep = '\t';
  char decimal = '.';
  std::string x_columns = "One";
  std::map<std::string, std::string> header;          // file header tags
  std::map<std::string, std::vector<std::string>> seg;  // segment header: tag -> per-channel values
  int channels = 0;
  std::vector<std::string> names;
  DataTable table;
  std::vector<std::string> notes;
};

[[noreturn]] void fail(const Lvm& f, std::size_t line, const std::string& what) {
  check_interrupt();  // a read that a signal cut short is no malformed file
  throw InputError(one_line("LVM file '" + f.path + "': line " + std::to_string(line) + ": " + what));
}

// The column of channel i's values (and of its x, for X_Columns Multi).
std::size_t value_column(const Lvm& f, int i) { return f.x_columns == "Multi" ? 2 * i + 1 : i + 1; }

bool number(const Lvm& f, std::string cell, double& v) {
  cell = trim(cell);
  if (f.decimal == ',') std::replace(cell.begin(), cell.end(), ',', '.');
  return parse_number(cell, v);
}

// Half a unit of the last digit a number is written to: "0.000977" → 5e-7, "9.765625E-4" → 5e-11,
// "1E-3" → 5e-4 (a decimal comma counts as the point).
double written_rounding(std::string cell) {
  cell = trim(cell);
  const auto e = cell.find_first_of("eE");
  const std::string mantissa = cell.substr(0, e);
  const int exponent = e == std::string::npos ? 0 : std::atoi(cell.c_str() + e + 1);
  const auto point = mantissa.find_first_of(".,");
  const int decimals = point == std::string::npos ? 0 : static_cast<int>(mantissa.size() - point - 1);
  return 0.5 * std::pow(10.0, exponent - decimals);
}

// The same on a trimmed cell of a data row.
bool number_view(const Lvm& f, std::string_view cell, double& v) {
  if (f.decimal != ',' || cell.find(',') == std::string_view::npos) return parse_number(cell, v);
  std::string c(cell);
  std::replace(c.begin(), c.end(), ',', '.');
  return parse_number(c, v);
}

// The per-channel value of a segment tag, or "".
std::string seg_value(const Lvm& f, const std::string& tag, int i) {
  const auto it = f.seg.find(tag);
  if (it == f.seg.end()) return "";
  const std::size_t c = value_column(f, i) - 1;  // (the tag's own column is dropped)
  return c < it->second.size() ? trim(it->second[c]) : std::string();
}

Lvm parse_stream(std::istream& in, const std::string& path) {
  Lvm f;
  f.path = path;
  f.table.source = path;
  std::string line;
  std::size_t lineno = 0;
  auto next = [&](std::string& l) {
    if (!std::getline(in, l)) return false;
    ++lineno;
    if (!l.empty() && l.back() == '\r') l.pop_back();
    if (lineno % 4096 == 0) check_interrupt();
    return true;
  };
  if (!next(line) || line.rfind(kMagic, 0) != 0) {
    check_interrupt();
    fail(f, 1, "does not start with 'LabVIEW Measurement'");
  }
  if (line.size() > std::string(kMagic).size() && line[std::string(kMagic).size()] == ',') f.sep = ',';
  // The file header.
  bool ended = false;
  while (next(line)) {
    const auto fl = split(line, f.sep);
    const std::string tag = trim(fl[0]);
    if (tag == kEnd) {
      ended = true;
      break;
    }
    if (!tag.empty()) f.header[tag] = fl.size() > 1 ? trim(fl[1]) : std::string();
    // "Decimal_Separator,," in a comma-separated file: the value is the comma itself.
    if (tag == "Decimal_Separator" && f.sep == ',' && fl.size() >= 3 && trim(fl[1]).empty() && trim(fl[2]).empty())
      f.header[tag] = ",";
  }
  if (!ended) fail(f, lineno, "the file header has no ***End_of_Header***");
  if (const auto s = f.header.find("Separator"); s != f.header.end()) {
    if (s->second == "Comma") f.sep = ',';
    else if (s->second == "Tab") f.sep = '\t';
    else fail(f, 1, "Separator must be Tab or Comma, got '" + shorten(s->second) + "'");
  }
  if (const auto d = f.header.find("Decimal_Separator"); d != f.header.end()) {
    if (d->second != "." && d->second != ",") fail(f, 1, "Decimal_Separator must be '.' or ',', got '" + shorten(d->second) + "'");
    f.decimal = d->second[0];
  }
  if (f.sep == ',' && f.decimal == ',')
    fail(f, 1, "a comma is both the separator and the decimal mark: the fields cannot be told apart");
  if (const auto x = f.header.find("X_Columns"); x != f.header.end()) {
    if (x->second != "No" && x->second != "One" && x->second != "Multi")
      fail(f, 1, "X_Columns must be No, One or Multi, got '" + shorten(x->second) + "'");
    f.x_columns = x->second;
  }
  // The segment header (blank rows and special blocks before it skipped).
  ended = false;
  bool special = false;
  while (next(line)) {
    const auto fl = split(line, f.sep);
    const std::string tag = trim(fl[0]);
    if (tag == "***Start_Special***") special = true;
    if (special) {
      if (tag == "***End_Special***") special = false;
      continue;
    }
    if (tag == kEnd) {
      ended = true;
      break;
    }
    if (tag.empty()) continue;
    f.seg[tag] = std::vector<std::string>(fl.begin() + 1, fl.end());
  }
  if (!ended) fail(f, lineno, "no segment header (Channels, Samples, ... ended by ***End_of_Header***)");
  {
    double n = 0;
    const auto c = f.seg.find("Channels");
    if (c == f.seg.end() || c->second.empty() || !parse_decimal(trim(c->second[0]), n) || n < 1 || n != std::floor(n) || n > 100000)
      fail(f, lineno, "the segment header states no Channels count");
    f.channels = static_cast<int>(n);
  }
  for (int i = 0; i < f.channels; ++i) {
    const std::string d = seg_value(f, "X_Dimension", i);
    if (!d.empty() && d != "Time")
      fail(f, lineno, "channel " + std::to_string(i + 1) + "'s X_Dimension is '" + shorten(d) + "': not a time record");
  }
  // The column names (LabVIEW writes them; a file without the row gets "Untitled", as LabVIEW's
  // own default names).
  bool pending = false;  // the row read in place of the names is the first data row
  if (next(line)) {
    if (trim(split(line, f.sep)[0]) == "X_Value") {
      const auto fl = split(line, f.sep);
      for (int i = 0; i < f.channels; ++i) {
        const std::size_t c = value_column(f, i);
        f.names.push_back(c < fl.size() ? windows1252_to_utf8(trim(fl[c])) : std::string());
      }
    } else {
      pending = true;
    }
  }
  for (int i = 0; i < f.channels; ++i)
    if (static_cast<std::size_t>(i) >= f.names.size() || f.names[i].empty()) {
      if (static_cast<std::size_t>(i) >= f.names.size()) f.names.push_back("");
      f.names[i] = i == 0 ? "Untitled" : "Untitled " + std::to_string(i);
    }
  // The data rows, to a blank row or the end.
  std::vector<std::vector<double>> y(f.channels), x(f.x_columns == "Multi" ? f.channels : 1);
  std::vector<std::size_t> count(f.channels, 0);
  std::vector<std::string_view> fl;
  while (pending || next(line)) {
    pending = false;
    if (trim_view(line).empty() || line.find_first_not_of(f.sep) == std::string::npos) {
      // A blank row ends the segment: anything after it is a further segment.
      while (next(line))
        if (!trim(line).empty() && line.find_first_not_of(f.sep) != std::string::npos)
          fail(f, lineno, "a second segment begins here; this reader takes files of one segment (one write, or "
                          "Multi_Headings No)");
      break;
    }
    split_view(line, f.sep, fl);
    const std::string_view first = trim_view(fl[0]);
    if (first == kMagic || first == "Channels" || first == kEnd || first == "X_Value" || first == "***Start_Special***")
      fail(f, lineno, "a second segment begins here; this reader takes files of one segment (one write, or Multi_Headings No)");
    if (y[0].size() >= static_cast<std::size_t>(limits::kMaxSamples))
      fail(f, lineno, "more than " + format_value(limits::kMaxSamples) + " samples (the limit of one record)");
    for (int i = 0; i < f.channels; ++i) {
      const std::size_t c = value_column(f, i);
      const std::string_view cell = c < fl.size() ? trim_view(fl[c]) : std::string_view();
      if (cell.empty()) {
        y[i].push_back(std::nan(""));  // no sample: allowed only where every row of the channel is empty
        continue;
      }
      double v = 0;
      if (!number_view(f, cell, v))
        fail(f, lineno, "column " + std::to_string(c + 1) + " ('" + shorten(f.names[i]) + "'): not a number, got '" + shorten(std::string(cell)) + "'");
      if (!std::isfinite(v)) fail(f, lineno, "column " + std::to_string(c + 1) + " ('" + shorten(f.names[i]) + "'): must be finite, got " + std::string(cell));
      y[i].push_back(v);
      ++count[i];
    }
    for (std::size_t k = 0; k < x.size(); ++k) {
      if (f.x_columns == "No") break;
      const std::size_t c = f.x_columns == "Multi" ? 2 * k : 0;
      const std::string_view cell = c < fl.size() ? trim_view(fl[c]) : std::string_view();
      double v = std::nan("");
      if (!cell.empty() && !number_view(f, cell, v))
        fail(f, lineno, "column " + std::to_string(c + 1) + " (X_Value): not a number, got '" + shorten(std::string(cell)) + "'");
      x[k].push_back(v);
    }
  }
  check_interrupt();
  const std::size_t n = y[0].size();
  if (n < 2) fail(f, lineno, "needs at least 2 data rows, got " + std::to_string(n));
  // Channels with no sample at all are left out (a channel the task held but did not write); the
  // rest must have a sample on every row.
  DataTable& tab = f.table;
  tab.time_name = "X_Value";
  int first = -1;
  for (int i = 0; i < f.channels; ++i) {
    if (count[i] == 0) {
      f.notes.push_back("channel '" + f.names[i] + "' holds no samples and is left out");
      continue;
    }
    if (count[i] != n)
      throw InputError(one_line("LVM file '" + path + "': channel '" + f.names[i] + "' has " + std::to_string(count[i]) +
                                " samples, the file " + std::to_string(n) +
                                " rows: the channels of one record share one time grid"));
    if (first < 0) first = i;
    tab.names.push_back(f.names[i]);
    tab.units.push_back(windows1252_to_utf8(seg_value(f, "Y_Unit_Label", i)));
    tab.columns.push_back(std::move(y[i]));
  }
  if (first < 0) fail(f, lineno, "no channel holds samples");
  // Time.
  double x0 = 0, dx = 0;
  const bool have_dx = number(f, seg_value(f, "Delta_X", first), dx) && dx > 0 && std::isfinite(dx);
  if (!number(f, seg_value(f, "X0", first), x0) || !std::isfinite(x0)) x0 = 0.0;
  if (f.x_columns == "No") {
    if (!have_dx) fail(f, lineno, "X_Columns No needs a Delta_X > 0 for channel '" + f.names[first] + "'");
    tab.t.resize(n);
    for (std::size_t k = 0; k < n; ++k) tab.t[k] = x0 + static_cast<double>(k) * dx;
    tab.stated_step = dx;  // the times are the file's Delta_X, as written
    tab.stated_step_rounding = written_rounding(seg_value(f, "Delta_X", first));
  } else {
    const std::vector<double>& t = x[f.x_columns == "Multi" ? static_cast<std::size_t>(first) : 0];
    for (std::size_t k = 0; k < n; ++k)
      if (!std::isfinite(t[k])) throw InputError(one_line("LVM file '" + path + "': row " + std::to_string(k + 1) + " of the data has no X_Value"));
    if (f.x_columns == "Multi")
      for (int i = 0; i < f.channels; ++i) {
        if (count[i] == 0) continue;
        for (std::size_t k = 0; k < n; ++k)
          if (!(std::abs(x[i][k] - t[k]) <= 1e-9 * std::max(1.0, std::abs(t.back() - t.front()))))
            throw InputError(one_line("LVM file '" + path + "': channel '" + f.names[i] + "' is sampled at other times than '" +
                                      f.names[first] + "' (row " + std::to_string(k + 1) + "): one record shares one time grid"));
      }
    tab.t = std::move(x[f.x_columns == "Multi" ? static_cast<std::size_t>(first) : 0]);  // (t is no longer used)
    if (have_dx && n > 1) {
      const double step = (tab.t.back() - tab.t.front()) / static_cast<double>(n - 1);
      if (std::abs(step - dx) > 1e-6 * dx)
        f.notes.push_back("Delta_X " + format_value(dx) + " s disagrees with the X_Value column's mean step " + format_value(step) +
                          " s (a decimated file keeps the original Delta_X); the X_Value column is used");
    }
  }
  for (std::size_t k = 1; k < n; ++k)
    if (!(tab.t[k] > tab.t[k - 1]))
      throw InputError(one_line("LVM file '" + path + "': data row " + std::to_string(k + 1) + ": time must be strictly increasing, got " +
                                format_value(tab.t[k]) + " after " + format_value(tab.t[k - 1]) +
                                (f.header.count("Multi_Headings") && f.header["Multi_Headings"] == "No"
                                     ? " (appended writes restart their x)"
                                     : "")));
  return f;
}

Lvm parse(const std::string& path) {
  InputFileStream in(path, "LVM file '" + path + "'");
  return parse_stream(in, path);
}

}  // namespace

DataTable read_lvm_text(const std::string& text, const std::string& source) {
  std::istringstream in(text);
  return parse_stream(in, source).table;
}

bool looks_like_lvm(const std::string& head) { return head.rfind(kMagic, 0) == 0; }

DataTable read_lvm(const std::string& path) { return parse(path).table; }

namespace {

// A number as LabVIEW's "%.17g" writes it: 17 significant digits, which read back to the same
// double (std::to_chars: no locale, so the decimal mark is always '.').
void put_number(std::string& out, double v) {
  char buf[40];
  const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, 17);
  out.append(buf, r.ptr);
}

// Whether a name or unit reads back as written: no separator, line break or other control
// character, no blanks at either end (the reader trims cells), UTF-8.
std::string cell_problem(const std::string& s) {
  for (unsigned char c : s)
    if (c < 0x20 || c == 0x7F) return "holds a tab, line break or other control character";
  if (!s.empty() && (s.front() == ' ' || s.back() == ' ')) return "begins or ends with a blank";
  if (first_invalid_utf8(s) != std::string::npos) return "is not UTF-8 text";
  return "";
}

}  // namespace

void write_lvm(const DataTable& tab, const std::string& path) {
  const std::string where = "LVM file '" + path + "'";
  try {
    check_table(tab);
  } catch (const InputError& e) {
    throw InputError(one_line(where + ": cannot be written: " + e.what()));
  }
  auto refuse = [&](const std::string& what) { throw InputError(one_line(where + ": cannot be written: " + what)); };
  for (std::size_t j = 0; j < tab.names.size(); ++j) {
    const std::string& n = tab.names[j];
    if (const std::string p = cell_problem(n); !p.empty()) refuse("column name '" + shorten(n) + "' " + p);
    if (n == "X_Value") refuse("a column named 'X_Value' (the name of the file's time column)");
    if (const std::string p = cell_problem(tab.unit(static_cast<int>(j))); !p.empty())
      refuse("the unit '" + shorten(tab.unit(static_cast<int>(j))) + "' of column '" + shorten(n) + "' " + p);
  }
  const std::size_t channels = tab.names.size(), n = tab.t.size();
  // The write's date and time, as LabVIEW stamps a file (local time).
  char date[32] = "", clock[32] = "";
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  if (localtime_r(&now, &tm)) {
    std::strftime(date, sizeof date, "%Y/%m/%d", &tm);
    std::strftime(clock, sizeof clock, "%H:%M:%S", &tm);
  }
  std::string out;
  out.reserve(1024 + n * (channels + 1) * 25);
  out += std::string(kMagic) + "\t\n";
  out += "Writer_Version\t2\nReader_Version\t2\nSeparator\tTab\nDecimal_Separator\t.\nMulti_Headings\tNo\n"
         "X_Columns\tOne\nTime_Pref\tRelative\n";
  out += std::string("Date\t") + date + "\nTime\t" + clock + "\n";
  out += std::string(kEnd) + "\t\n\t\n";
  // The segment header: one value per channel, in the channel's own column.
  auto row = [&](const char* tag, auto value) {
    out += tag;
    for (std::size_t j = 0; j < channels; ++j) {
      out += '\t';
      value(j);
    }
    out += "\t\n";
  };
  out += "Channels\t" + std::to_string(channels) + "\t\n";
  row("Samples", [&](std::size_t) { out += std::to_string(n); });
  row("Date", [&](std::size_t) { out += date; });
  row("Time", [&](std::size_t) { out += clock; });
  row("Y_Unit_Label", [&](std::size_t j) { out += tab.unit(static_cast<int>(j)); });
  row("X_Dimension", [&](std::size_t) { out += "Time"; });
  // X0 and Delta_X: the first time and the mean step (the X_Value column holds every time).
  const double step = (tab.t.back() - tab.t.front()) / static_cast<double>(n - 1);
  row("X0", [&](std::size_t) { put_number(out, tab.t.front()); });
  row("Delta_X", [&](std::size_t) { put_number(out, step); });
  out += std::string(kEnd) + "\t\n";
  out += "X_Value";
  for (const auto& name : tab.names) out += '\t' + name;
  out += "\tComment\n";
  for (std::size_t k = 0; k < n; ++k) {
    if (k % 4096 == 0) check_interrupt();
    put_number(out, tab.t[k]);
    for (const auto& c : tab.columns) {
      out += '\t';
      put_number(out, c[k]);
    }
    out += '\n';
  }
  write_text_atomic(path, out);
}

DataFileInfo describe_lvm(const std::string& path) {
  const Lvm f = parse(path);
  DataFileInfo info = describe_table(f.table, "lvm");
  info.notes.push_back("X_Columns " + f.x_columns + ", separator " + (f.sep == '\t' ? "Tab" : "Comma") + ", decimal mark '" +
                       std::string(1, f.decimal) + "'");
  info.notes.insert(info.notes.end(), f.notes.begin(), f.notes.end());
  return info;
}

}  // namespace scoleid::io
