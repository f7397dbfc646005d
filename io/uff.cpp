// Reader for the Universal File Format (UFF / UNV). The layout of every supported dataset is
// stated in scoleid/io/uff.h. The file is walked line by line; a dataset is the text between an
// opening and a closing "-1" line, except for the binary block of a 58b, which is skipped by its
// byte count (it may contain "-1" lines and line breaks of its own).
#include "scoleid/io/uff.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <sstream>
#include <string_view>
#include <system_error>

#include "scoleid/io/error.h"
#include "scoleid/io/input_file.h"
#include "scoleid/io/interrupt.h"
#include "scoleid/io/limits.h"
#include "scoleid/io/validation.h"

namespace scoleid::io::uff {
namespace {

constexpr double kPi = 3.14159265358979323846;
const std::size_t kMaxValues = static_cast<std::size_t>(limits::kMaxSamples);
const std::size_t kNotFound = static_cast<std::size_t>(-1);

// ---------------------------------------------------------------------------------------------
// Text: characters, fields, numbers.

bool is_blank_char(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v'; }

std::string_view trim(std::string_view s) {
  while (!s.empty() && is_blank_char(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_blank_char(s.back())) s.remove_suffix(1);
  return s;
}

bool blank(std::string_view s) { return trim(s).empty(); }

bool is_none(std::string_view s) {
  s = trim(s);
  if (s.size() != 4) return false;
  for (std::size_t i = 0; i < 4; ++i)
    if ((s[i] & ~0x20) != "NONE"[i]) return false;
  return true;
}

// Length of the well-formed UTF-8 sequence that starts at s[i], or 0.
std::size_t utf8_length(std::string_view s, std::size_t i) {
  const auto c = static_cast<unsigned char>(s[i]);
  const std::size_t len = c >= 0xF0 ? 4 : c >= 0xE0 ? 3 : c >= 0xC0 ? 2 : 0;
  if (len == 0 || i + len > s.size()) return 0;
  return first_invalid_utf8(std::string(s.substr(i, len))) == std::string::npos ? len : 0;
}

// A line as characters, the unit of Fortran field widths: a UTF-8 sequence is one character; any
// other byte is one character too, read as Latin-1 (U+FFFD for 0x80-0x9F). text() is UTF-8.
class Columns {
 public:
  explicit Columns(std::string_view line) {
    ascii_ = std::all_of(line.begin(), line.end(), [](char c) { return static_cast<unsigned char>(c) < 0x80; });
    if (ascii_) {
      text_.assign(line);
      return;
    }
    for (std::size_t i = 0; i < line.size();) {
      starts_.push_back(text_.size());
      const auto c = static_cast<unsigned char>(line[i]);
      const std::size_t len = c < 0x80 ? 1 : utf8_length(line, i);
      if (len > 0) {
        text_.append(line.substr(i, len));
        i += len;
        continue;
      }
      if (c < 0xA0) {
        text_ += "\xEF\xBF\xBD";
      } else {
        text_.push_back(static_cast<char>(0xC0 | (c >> 6)));
        text_.push_back(static_cast<char>(0x80 | (c & 0x3F)));
      }
      ++i;
    }
    starts_.push_back(text_.size());
  }
  std::size_t size() const { return ascii_ ? text_.size() : starts_.size() - 1; }
  const std::string& text() const { return text_; }
  // Characters [first, first + width), clipped to the line, trimmed.
  std::string field(std::size_t first, std::size_t width) const {
    if (first >= size()) return {};
    const std::size_t last = std::min(size(), first + width);
    const std::size_t b = ascii_ ? first : starts_[first], e = ascii_ ? last : starts_[last];
    return std::string(trim(std::string_view(text_).substr(b, e - b)));
  }

 private:
  bool ascii_ = true;
  std::string text_;
  std::vector<std::size_t> starts_;  // byte offset of each character in text_, then text_.size()
};

std::string text_of(std::string_view line) { return std::string(trim(Columns(line).text())); }

std::vector<std::string> tokens(std::string_view s) {
  std::vector<std::string> out;
  std::size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && is_blank_char(s[i])) ++i;
    const std::size_t b = i;
    while (i < s.size() && !is_blank_char(s[i])) ++i;
    if (i > b) out.emplace_back(s.substr(b, i - b));
  }
  return out;
}

std::vector<std::string> cut(const Columns& c, const std::vector<int>& widths) {
  std::vector<std::string> out;
  std::size_t at = 0;
  for (const int w : widths) {
    out.push_back(c.field(at, static_cast<std::size_t>(w)));
    at += static_cast<std::size_t>(w);
  }
  return out;
}

// A Fortran real: optional sign and digits, an optional exponent introduced by E or D (either
// case) or by its sign alone ("1.5-105"). Finite values only.
bool parse_real(std::string_view s, double& v) {
  s = trim(s);
  if (s.empty() || s.size() > 64) return false;
  char buf[80];
  std::size_t n = 0, i = 0;
  if (s[0] == '+') {
    if (s.size() == 1 || s[1] == '+' || s[1] == '-') return false;
    i = 1;
  }
  bool exponent = false;
  for (; i < s.size(); ++i) {
    char c = s[i];
    if (c == 'D' || c == 'd' || c == 'E' || c == 'e') {
      c = 'e';
      exponent = true;
    } else if ((c == '+' || c == '-') && i > 0 && !exponent &&
               ((s[i - 1] >= '0' && s[i - 1] <= '9') || s[i - 1] == '.')) {
      buf[n++] = 'e';
      exponent = true;
    }
    buf[n++] = c;
  }
  const auto r = std::from_chars(buf, buf + n, v, std::chars_format::general);
  return r.ec == std::errc() && r.ptr == buf + n && std::isfinite(v);
}

bool parse_int(std::string_view s, int& v) {
  s = trim(s);
  if (!s.empty() && s[0] == '+') {
    s.remove_prefix(1);
    if (s.empty() || s[0] == '-' || s[0] == '+') return false;
  }
  if (s.empty()) return false;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  return r.ec == std::errc() && r.ptr == s.data() + s.size();
}

std::string in_quotes(std::string_view s) {
  if (s.size() > 80) return "'" + std::string(s.substr(0, 77)) + "...'";
  return "'" + std::string(s) + "'";
}

// Kinds of a record's fields: 'I' integer, 'R' real, 'S' text; lower case: may be blank.
bool fits(const std::vector<std::string>& f, const std::string& kinds) {
  if (f.size() > kinds.size()) return false;
  for (std::size_t i = 0; i < kinds.size(); ++i) {
    const std::string v = i < f.size() ? f[i] : std::string();
    const char k = kinds[i];
    if (v.empty()) {
      if (k == 'I' || k == 'R' || k == 'S') return false;
      continue;
    }
    int n = 0;
    double d = 0;
    if ((k == 'I' || k == 'i') && !parse_int(v, n)) return false;
    if ((k == 'R' || k == 'r') && !parse_real(v, d)) return false;
  }
  return true;
}

// The fields of a fixed-format record. Blank-separated tokens are preferred when the record holds
// only numbers and there is one token per field (a writer's wider columns); else the fields cut
// at `widths` (blank fields, numbers that touch); else the tokens, missing ones blank. When
// nothing fits, the tokens if one per field, else the cut: callers convert the fields and so
// report the first one that does not fit.
std::vector<std::string> record_fields(const Columns& c, const std::vector<int>& widths, const std::string& kinds) {
  auto t = tokens(c.text());
  const bool one_per_field = kinds.find_first_of("Ss") == std::string::npos && t.size() == kinds.size();
  if (one_per_field && fits(t, kinds)) return t;
  auto f = cut(c, widths);
  if (fits(f, kinds)) return f;
  if (one_per_field || fits(t, kinds)) {
    t.resize(kinds.size());
    return t;
  }
  return f;
}

// ---------------------------------------------------------------------------------------------
// Lines of the file.

struct Line {
  std::string_view text;  // without its line break
  std::size_t number = 0;
};

// Walks the bytes line by line; a line ends at LF, CR LF or CR.
class Cursor {
 public:
  explicit Cursor(std::string_view s) : s_(s) {
    if (s_.substr(0, 3) == "\xEF\xBB\xBF") pos_ = 3;
  }
  bool done() const { return pos_ >= s_.size(); }
  std::size_t pos() const { return pos_; }
  std::string_view bytes() const { return s_; }
  Line next() {
    if (line_ % 4096 == 0) check_interrupt();  // a file of millions of lines takes seconds
    const std::size_t b = pos_;
    std::size_t e = s_.find_first_of("\r\n", b);
    if (e == std::string_view::npos) e = s_.size();
    pos_ = e;
    skip_break();
    return Line{s_.substr(b, e - b), line_++};
  }
  void skip_blank_lines() {
    while (!done()) {
      const std::size_t save = pos_, line = line_;
      if (!blank(next().text)) {
        pos_ = save;
        line_ = line;
        return;
      }
    }
  }
  // Moves to byte `p` (>= pos()), counting the line breaks passed.
  void skip_to(std::size_t p) {
    while (pos_ < p) {
      const char c = s_[pos_++];
      if (c == '\n' || (c == '\r' && (pos_ >= s_.size() || s_[pos_] != '\n'))) ++line_;
    }
  }

 private:
  void skip_break() {
    if (pos_ < s_.size() && s_[pos_] == '\r') {
      ++pos_;
      if (pos_ < s_.size() && s_[pos_] == '\n') ++pos_;
    } else if (pos_ < s_.size() && s_[pos_] == '\n') {
      ++pos_;
    }
  }
  std::string_view s_;
  std::size_t pos_ = 0;
  std::size_t line_ = 1;
};

bool is_delimiter(std::string_view line) { return trim(line) == "-1"; }

// ---------------------------------------------------------------------------------------------
// Messages.

[[noreturn]] void fail_file(const std::string& source, std::size_t line, const std::string& what,
                            const std::string& got) {
  throw InputError(one_line("UFF file '" + source + "', line " + std::to_string(line) + ": " + what + ", got " + got));
}

// One dataset being read: where it is, and the conversions that report a bad field.
struct Rec {
  const std::string* source = nullptr;
  std::size_t record = 0;
  std::string dataset;   // "58", "58b", "55", ...
  std::size_t line = 0;  // its dataset-number line

  [[noreturn]] void fail(std::size_t at, const std::string& field, const std::string& requirement,
                         const std::string& got) const {
    std::ostringstream m;
    m << "UFF file '" << *source << "', record " << record << " (dataset " << dataset << " at line " << line << ")";
    if (at != 0) m << ", line " << at;
    m << ": " << field << " " << requirement << ", got " << got;
    throw InputError(one_line(m.str()));
  }
  int integer(const Line& l, const std::string& field, const std::string& text, bool required) const {
    int v = 0;
    if (text.empty() && !required) return 0;
    if (!parse_int(text, v))
      fail(l.number, field, "must be an integer", text.empty() ? "a blank field" : in_quotes(text));
    return v;
  }
  double real(const Line& l, const std::string& field, const std::string& text, bool required) const {
    double v = 0;
    if (text.empty() && !required) return 0;
    if (!parse_real(text, v))
      fail(l.number, field, "must be a finite number", text.empty() ? "a blank field" : in_quotes(text));
    return v;
  }
  int to_int(const Line& l, const std::string& field, double v) const {
    if (!(std::floor(v) == v && std::abs(v) <= 2147483647.0))
      fail(l.number, field, "must be an integer", format_value(v));
    return static_cast<int>(v);
  }
};

// The numbers of one data line, appended to `out`: its blank-separated tokens when every one is
// a number; else fixed-width fields cycling through `widths` (numbers that touch, such as
// "4.1E+03-3.1E+03"), of which blank ones may only end the line. Errors name the field `what`
// followed by its 1-based index in `out`.
void line_numbers(const Rec& r, const Line& l, const std::vector<int>& widths, const std::string& what,
                  std::vector<double>& out) {
  const Columns c(l.text);
  const std::size_t before = out.size();
  const auto t = tokens(c.text());
  double v = 0;
  for (const auto& s : t) {
    if (!parse_real(s, v)) break;
    out.push_back(v);
  }
  if (out.size() == before + t.size()) return;
  out.resize(before);
  std::vector<std::string> f;
  for (std::size_t at = 0, k = 0; at < c.size(); ++k) {
    const auto w = static_cast<std::size_t>(widths[k % widths.size()]);
    f.push_back(c.field(at, w));
    at += w;
  }
  while (!f.empty() && f.back().empty()) f.pop_back();
  for (std::size_t i = 0; i < f.size(); ++i) {
    if (!parse_real(f[i], v))
      r.fail(l.number, what + " " + std::to_string(before + i + 1), "must be a finite number",
             f[i].empty() ? "a blank field" : in_quotes(f[i]));
    out.push_back(v);
  }
}

// Numbers from body[i...] until at least `count` are read (lines are read whole); blank lines are
// skipped. Fails when the dataset ends first.
std::vector<double> numbers_from(const Rec& r, const std::vector<Line>& body, std::size_t& i, std::size_t count,
                                 const std::vector<int>& widths, const std::string& what) {
  std::vector<double> v;
  while (v.size() < count) {
    if (i >= body.size())
      r.fail(body.empty() ? 0 : body.back().number, what + "s", "must number " + std::to_string(count),
             std::to_string(v.size()) + " before the end of the dataset");
    if (!blank(body[i].text)) line_numbers(r, body[i], widths, what, v);
    ++i;
  }
  return v;
}

// ---------------------------------------------------------------------------------------------
// Datasets 151, 164, 15, 2411.

std::string join_date(const Columns& c) {
  const std::string d = c.field(0, 10), t = c.field(10, 10);
  return d.empty() ? t : t.empty() ? d : d + " " + t;
}

void read_header(const Rec& r, const std::vector<Line>& body, File& out) {
  if (body.size() < 7)
    r.fail(body.empty() ? 0 : body.back().number, "header", "must have 7 lines", std::to_string(body.size()));
  Header h;
  h.record = r.record;
  h.line = r.line;
  h.model_name = text_of(body[0].text);
  h.description = text_of(body[1].text);
  h.application = text_of(body[2].text);
  const Columns created(body[3].text);
  h.created = join_date(created);
  // Like pyuff, a version or file-type field that is not an integer reads as 0: some writers
  // fill this cosmetic record loosely.
  const auto f = cut(created, {10, 10, 10, 10, 10});
  parse_int(f[2], h.version);
  parse_int(f[3], h.sub_version);
  parse_int(f[4], h.file_type);
  h.saved = join_date(Columns(body[4].text));
  h.program = text_of(body[5].text);
  h.written = join_date(Columns(body[6].text));
  if (!out.header) out.header = h;
}

void read_units(const Rec& r, const std::vector<Line>& body, File& out) {
  if (body.empty()) r.fail(0, "units line", "must follow the dataset number", "the end of the dataset");
  Units u;
  u.record = r.record;
  u.line = r.line;
  const Columns c(body[0].text);
  const auto f = cut(c, {10, 20, 10});
  u.code = r.integer(body[0], "units code", f[0], true);
  u.description = f[1];
  u.temperature_mode = r.integer(body[0], "temperature mode", f[2], false);
  const char* names[] = {"length factor", "force factor", "temperature factor", "temperature offset"};
  double* slots[] = {&u.length, &u.force, &u.temperature, &u.temperature_offset};
  std::size_t k = 0;
  for (std::size_t i = 1; i < body.size(); ++i)
    for (const auto& t : tokens(body[i].text)) {
      if (k == 4) r.fail(body[i].number, "unit factors", "must be 4 numbers", "more");
      *slots[k] = r.real(body[i], names[k], t, true);
      if (k < 3 && *slots[k] == 0) r.fail(body[i].number, names[k], "must not be zero", in_quotes(t));
      ++k;
    }
  if (k < 4) r.fail(body.back().number, "unit factors", "must be 4 numbers", std::to_string(k));
  if (!out.units) out.units = u;
}

void read_nodes15(const Rec& r, const std::vector<Line>& body, File& out) {
  for (const Line& l : body) {
    if (blank(l.text)) continue;
    const auto f = record_fields(Columns(l.text), {10, 10, 10, 10, 13, 13, 13}, "IiiiRRR");
    Node n;
    n.id = r.integer(l, "node label", f[0], true);
    n.coordinate_system = r.integer(l, "definition coordinate system", f[1], false);
    n.displacement_system = r.integer(l, "displacement coordinate system", f[2], false);
    n.color = r.integer(l, "colour", f[3], false);
    n.x = r.real(l, "x", f[4], true);
    n.y = r.real(l, "y", f[5], true);
    n.z = r.real(l, "z", f[6], true);
    n.dataset = 15;
    n.record = r.record;
    out.nodes.push_back(n);
  }
}

void read_nodes2411(const Rec& r, const std::vector<Line>& body, File& out) {
  std::vector<const Line*> lines;
  for (const Line& l : body)
    if (!blank(l.text)) lines.push_back(&l);
  for (std::size_t i = 0; i < lines.size(); i += 2) {
    const Line& a = *lines[i];
    const auto f = record_fields(Columns(a.text), {10, 10, 10, 10}, "Iiii");
    Node n;
    n.id = r.integer(a, "node label", f[0], true);
    if (i + 1 >= lines.size())
      r.fail(a.number, "node " + std::to_string(n.id), "must have a coordinates line", "the end of the dataset");
    n.coordinate_system = r.integer(a, "export coordinate system", f[1], false);
    n.displacement_system = r.integer(a, "displacement coordinate system", f[2], false);
    n.color = r.integer(a, "colour", f[3], false);
    const Line& b = *lines[i + 1];
    const auto x = record_fields(Columns(b.text), {25, 25, 25}, "RRR");
    n.x = r.real(b, "x", x[0], true);
    n.y = r.real(b, "y", x[1], true);
    n.z = r.real(b, "z", x[2], true);
    n.dataset = 2411;
    n.record = r.record;
    out.nodes.push_back(n);
  }
}

// ---------------------------------------------------------------------------------------------
// Dataset 55.

void read_shape_kind(const Rec& r, const Line& l, Shape& s) {
  const auto f = record_fields(Columns(l.text), {10, 10, 10, 10, 10, 10}, "IIIIII");
  s.model_type = r.integer(l, "model type", f[0], true);
  s.analysis_type = r.integer(l, "analysis type", f[1], true);
  s.data_characteristic = r.integer(l, "data characteristic", f[2], true);
  s.specific_data_type = r.integer(l, "specific data type", f[3], true);
  s.data_type = r.integer(l, "data type", f[4], true);
  s.values_per_node = r.integer(l, "number of values per node", f[5], true);
  if (s.data_type != 2 && s.data_type != 4 && s.data_type != 5 && s.data_type != 6)
    r.fail(l.number, "data type", "must be 2 (real) or 5 (complex)", in_quotes(f[4]));
  const std::size_t per = static_cast<std::size_t>(std::max(s.values_per_node, 0)) * (s.is_complex() ? 2 : 1);
  if (s.values_per_node < 1 || per > kMaxValues)
    r.fail(l.number, "number of values per node", "must be between 1 and " + std::to_string(kMaxValues),
           in_quotes(f[5]));
}

void interpret_parameters(Shape& s) {
  const auto& p = s.real_parameters;
  auto at = [&](std::size_t k) { return k < p.size() ? p[k] : Shape::kNaN; };
  if (!s.int_parameters.empty()) s.load_case = s.int_parameters[0];
  if (s.int_parameters.size() > 1) s.mode_number = s.int_parameters[1];
  if (s.analysis_type == 2) {
    s.frequency_hz = at(0);
    s.modal_mass = at(1);
    s.damping_ratio = at(2);
    s.hysteretic_damping = at(3);
  } else if (s.analysis_type == 3 || s.analysis_type == 7) {
    s.eigenvalue_re = at(0);
    s.eigenvalue_im = at(1);
    s.modal_a_re = at(2);
    s.modal_a_im = at(3);
    s.modal_b_re = at(4);
    s.modal_b_im = at(5);
    const double mag = std::hypot(s.eigenvalue_re, s.eigenvalue_im);
    s.frequency_hz = mag / (2 * kPi);
    if (mag > 0) s.damping_ratio = -s.eigenvalue_re / mag;
  } else if (s.analysis_type == 5) {
    s.frequency_hz = at(0);
  }
}

// Records 7 and 8: the counts, the integer and the real parameters. Values past the counts on
// the last line read are ignored.
void read_shape_parameters(const Rec& r, const std::vector<Line>& body, std::size_t& i, Shape& s) {
  const Line& l7 = i < body.size() ? body[i] : body.back();
  auto ints = numbers_from(r, body, i, 2, {10}, "record 7 value");
  const int nint = r.to_int(l7, "number of integer parameters", ints[0]);
  const int nreal = r.to_int(l7, "number of real parameters", ints[1]);
  if (nint < 0 || nint > 100)
    r.fail(l7.number, "number of integer parameters", "must be between 0 and 100", std::to_string(nint));
  if (nreal < 0 || nreal > 100)
    r.fail(l7.number, "number of real parameters", "must be between 0 and 100", std::to_string(nreal));
  if (ints.size() < 2 + static_cast<std::size_t>(nint)) {
    const auto more = numbers_from(r, body, i, 2 + nint - ints.size(), {10}, "record 7 value");
    ints.insert(ints.end(), more.begin(), more.end());
  }
  for (int k = 0; k < nint; ++k)
    s.int_parameters.push_back(r.to_int(l7, "integer parameter " + std::to_string(k + 1), ints[2 + k]));
  if (nreal > 0) {
    auto reals = numbers_from(r, body, i, static_cast<std::size_t>(nreal), {13}, "record 8 value");
    reals.resize(static_cast<std::size_t>(nreal));
    s.real_parameters = std::move(reals);
  }
  interpret_parameters(s);
}

// The values of one node: 6 to a line, so ceil(count / 6) lines, unless the first line holds them
// all (a wider writer). Blank lines are skipped.
std::vector<double> node_values(const Rec& r, const std::vector<Line>& body, std::size_t& i, std::size_t count,
                                const std::string& what) {
  std::vector<double> v;
  const std::size_t lines = (count + 5) / 6;
  std::size_t read = 0, last = body[i - 1].number;
  while (read < lines && v.size() < count && i < body.size()) {
    const Line& l = body[i++];
    if (blank(l.text)) continue;
    line_numbers(r, l, {13}, what, v);
    last = l.number;
    ++read;
  }
  if (v.size() != count) r.fail(last, what + "s", "must number " + std::to_string(count), std::to_string(v.size()));
  return v;
}

void read_shape_nodes(const Rec& r, const std::vector<Line>& body, std::size_t& i, Shape& s) {
  const bool complex = s.is_complex();
  const std::size_t ndv = static_cast<std::size_t>(s.values_per_node), per = ndv * (complex ? 2 : 1);
  std::size_t total = 0;
  while (i < body.size()) {
    const Line& l = body[i++];
    if (blank(l.text)) continue;
    const int id = r.integer(l, "node label", std::string(trim(Columns(l.text).text())), true);
    const std::string what = "node " + std::to_string(id) + " value";
    const auto v = node_values(r, body, i, per, what);
    total += per;
    if (total > kMaxValues) r.fail(l.number, "values", "must number at most " + std::to_string(kMaxValues), "more");
    s.nodes.push_back(id);
    s.values.emplace_back(ndv);
    if (complex) s.values_im.emplace_back(ndv);
    for (std::size_t k = 0; k < ndv; ++k) {
      s.values.back()[k] = complex ? v[2 * k] : v[k];
      if (complex) s.values_im.back()[k] = v[2 * k + 1];
    }
  }
}

void read_shape(const Rec& r, const std::vector<Line>& body, File& out) {
  if (body.size() < 7)
    r.fail(body.empty() ? 0 : body.back().number, "header", "must have at least 7 lines", std::to_string(body.size()));
  Shape s;
  s.record = r.record;
  s.line = r.line;
  s.id1 = text_of(body[0].text);
  s.id2 = text_of(body[1].text);
  s.id3 = text_of(body[2].text);
  s.id4 = text_of(body[3].text);
  s.id5 = text_of(body[4].text);
  read_shape_kind(r, body[5], s);
  std::size_t i = 6;
  read_shape_parameters(r, body, i, s);
  read_shape_nodes(r, body, i, s);
  out.shapes.push_back(std::move(s));
}

// ---------------------------------------------------------------------------------------------
// Dataset 58 and 58b.

int read_direction(const Rec& r, const Line& l, const std::string& field, const std::string& text) {
  const int d = r.integer(l, field, text, false);
  if (d < -6 || d > 6) r.fail(l.number, field, "must be between -6 and 6", in_quotes(text));
  return d;
}

void read_dof(const Rec& r, const Line& l, Function& f) {
  const auto v = record_fields(Columns(l.text), {5, 10, 5, 10, 11, 10, 4, 11, 10, 4}, "Iiiisiisii");
  f.function_type = r.integer(l, "function type", v[0], true);
  f.function_id = r.integer(l, "function id", v[1], false);
  f.version = r.integer(l, "version number", v[2], false);
  f.load_case = r.integer(l, "load case", v[3], false);
  f.response_entity = v[4];
  f.response_node = r.integer(l, "response node", v[5], false);
  f.response_direction = read_direction(r, l, "response direction", v[6]);
  f.reference_entity = v[7];
  f.reference_node = r.integer(l, "reference node", v[8], false);
  f.reference_direction = read_direction(r, l, "reference direction", v[9]);
}

void read_form(const Rec& r, const Line& l, Function& f) {
  const auto v = record_fields(Columns(l.text), {10, 10, 10, 13, 13, 13}, "IIIRRr");
  f.ordinate_type = r.integer(l, "ordinate data type", v[0], true);
  if (f.ordinate_type != 2 && f.ordinate_type != 4 && f.ordinate_type != 5 && f.ordinate_type != 6)
    r.fail(l.number, "ordinate data type", "must be 2, 4, 5 or 6 (real/complex, single/double precision)",
           in_quotes(v[0]));
  const int points = r.integer(l, "num_pts", v[1], true);
  if (points < 1 || static_cast<std::size_t>(points) > kMaxValues)
    r.fail(l.number, "num_pts", "must be between 1 and " + std::to_string(kMaxValues), in_quotes(v[1]));
  f.points = static_cast<std::size_t>(points);
  const int spacing = r.integer(l, "abscissa spacing", v[2], true);
  if (spacing != 0 && spacing != 1)
    r.fail(l.number, "abscissa spacing", "must be 0 (uneven) or 1 (even)", in_quotes(v[2]));
  f.even = spacing == 1;
  f.abscissa_min = r.real(l, "abscissa minimum", v[3], true);
  f.abscissa_increment = r.real(l, "abscissa increment", v[4], true);
  f.z_axis_value = r.real(l, "z-axis value", v[5], false);
  if (f.even && f.points > 1 && !(f.abscissa_increment > 0))
    r.fail(l.number, "abscissa increment", "must be > 0 for even spacing", in_quotes(v[4]));
  f.value_bytes = (f.ordinate_type == 4 || f.ordinate_type == 6) ? 8 : 4;
}

void read_axis(const Rec& r, const Line& l, const std::string& name, Function::Axis& a) {
  const auto v = record_fields(Columns(l.text), {10, 5, 5, 5, 21, 21}, "Iiiiss");
  a.spec_type = r.integer(l, name + " specific data type", v[0], true);
  a.length_exp = r.integer(l, name + " length units exponent", v[1], false);
  a.force_exp = r.integer(l, name + " force units exponent", v[2], false);
  a.temperature_exp = r.integer(l, name + " temperature units exponent", v[3], false);
  a.label = v[4];
  a.unit = v[5];
}

// The 11 header lines (records 1-11).
Function function_header(const Rec& r, const std::vector<Line>& h) {
  Function f;
  f.record = r.record;
  f.line = r.line;
  f.id1 = text_of(h[0].text);
  f.id2 = text_of(h[1].text);
  f.id3 = text_of(h[2].text);
  f.id4 = text_of(h[3].text);
  f.id5 = text_of(h[4].text);
  read_dof(r, h[5], f);
  read_form(r, h[6], f);
  read_axis(r, h[7], "abscissa", f.abscissa);
  read_axis(r, h[8], "ordinate", f.ordinate);
  read_axis(r, h[9], "denominator", f.denominator);
  read_axis(r, h[10], "z-axis", f.z_axis);
  return f;
}

std::size_t values_per_point(const Function& f) { return (f.is_complex() ? 2 : 1) + (f.even ? 0 : 1); }

// Splits the values (in file order) into x, re, im.
void assign_values(const Rec& r, const Line& form, Function& f, const std::vector<double>& v) {
  const std::size_t n = f.points, k = values_per_point(f);
  f.x.resize(n);
  f.re.resize(n);
  if (f.is_complex()) f.im.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double* p = v.data() + i * k;
    std::size_t j = 0;
    f.x[i] = f.even ? f.abscissa_min + static_cast<double>(i) * f.abscissa_increment : p[j++];
    f.re[i] = p[j++];
    if (f.is_complex()) f.im[i] = p[j];
  }
  if (f.even && !std::isfinite(f.x.back()))
    r.fail(form.number, "abscissa increment", "must keep the abscissa finite", format_value(f.abscissa_increment));
}

std::vector<int> value_widths(const Function& f) {
  if (f.value_bytes == 4) return {13};
  if (f.even) return {20};
  return f.is_complex() ? std::vector<int>{13, 20, 20} : std::vector<int>{13, 20};
}

void read_ascii_function(const Rec& r, const std::vector<Line>& body, File& out) {
  if (body.size() < 11)
    r.fail(body.empty() ? 0 : body.back().number, "header", "must have 11 lines before the data",
           std::to_string(body.size()) + " lines");
  Function f = function_header(r, body);
  const Line& form = body[6];
  std::size_t bytes = 0;
  for (std::size_t i = 11; i < body.size(); ++i) bytes += body[i].text.size() + 1;
  const std::size_t expected = f.points * values_per_point(f);
  if (expected > bytes)
    r.fail(form.number, "num_pts", "must fit the " + std::to_string(bytes) + " bytes of data lines",
           std::to_string(f.points));
  std::vector<double> v;
  v.reserve(expected);
  const auto widths = value_widths(f);
  for (std::size_t i = 11; i < body.size(); ++i) {
    if (!blank(body[i].text)) line_numbers(r, body[i], widths, "value", v);
    if (v.size() > expected)
      r.fail(body[i].number, "value " + std::to_string(expected + 1),
             "is past the " + std::to_string(expected) + " values num_pts " + std::to_string(f.points) + " declares",
             "more values");
  }
  if (v.size() != expected)
    r.fail(form.number, "num_pts",
           "must match the data: " + std::to_string(v.size()) + " values, " + std::to_string(values_per_point(f)) +
               " per point",
           std::to_string(f.points));
  assign_values(r, form, f, v);
  out.functions.push_back(std::move(f));
}

struct BinaryLayout {
  bool big_endian = false;
  std::size_t n_bytes = 0;
};

// The fields after "58b" on the dataset-number line.
BinaryLayout binary_layout(const Rec& r, const Line& l) {
  auto t = tokens(l.text);
  t.erase(t.begin());
  t.resize(std::max<std::size_t>(t.size(), 4));
  BinaryLayout b;
  const int order = r.integer(l, "byte ordering", t[0], true);
  if (order != 1 && order != 2)
    r.fail(l.number, "byte ordering", "must be 1 (little endian) or 2 (big endian)", in_quotes(t[0]));
  b.big_endian = order == 2;
  const int fp = r.integer(l, "floating-point format", t[1], false);
  if (fp == 1 || fp == 3)
    r.fail(l.number, "floating-point format", "must be 2 (IEEE 754); DEC (1) and IBM (3) are not supported",
           in_quotes(t[1]));
  r.integer(l, "number of ASCII lines", t[2], false);
  const int n = r.integer(l, "n_bytes", t[3], true);
  if (n < 0) r.fail(l.number, "n_bytes", "must be >= 0", in_quotes(t[3]));
  b.n_bytes = static_cast<std::size_t>(n);
  return b;
}

// Offset just past the closing "-1" line when it follows a binary block ending at `end` (stray CR
// and LF bytes in between are tolerated), else kNotFound.
std::size_t closing_after(std::string_view s, std::size_t end) {
  std::size_t p = end;
  while (p < s.size() && (s[p] == '\r' || s[p] == '\n')) ++p;
  while (p < s.size() && s[p] == ' ') ++p;
  if (s.substr(p, 2) != "-1") return kNotFound;
  p += 2;
  while (p < s.size() && (s[p] == ' ' || s[p] == '\t')) ++p;
  if (p < s.size() && s[p] != '\r' && s[p] != '\n') return kNotFound;
  if (p < s.size() && s[p] == '\r') ++p;
  if (p < s.size() && s[p] == '\n') ++p;
  return p;
}

bool host_is_little_endian() {
  const std::uint16_t one = 1;
  unsigned char first = 0;
  std::memcpy(&first, &one, 1);
  return first == 1;
}

std::vector<double> decode_binary(const Rec& r, std::string_view block, int bytes, bool big_endian) {
  const bool swap = big_endian == host_is_little_endian();
  const std::size_t n = block.size() / static_cast<std::size_t>(bytes);
  std::vector<double> v(n);
  unsigned char b[8];
  for (std::size_t i = 0; i < n; ++i) {
    std::memcpy(b, block.data() + i * static_cast<std::size_t>(bytes), static_cast<std::size_t>(bytes));
    if (swap) std::reverse(b, b + bytes);
    if (bytes == 4) {
      float x = 0;
      std::memcpy(&x, b, 4);
      v[i] = x;
    } else {
      std::memcpy(&v[i], b, 8);
    }
    if (!std::isfinite(v[i]))
      r.fail(0, "binary value " + std::to_string(i + 1), "must be a finite number", format_value(v[i]));
  }
  return v;
}

// The 11 header lines after a 58b's dataset-number line.
std::vector<Line> binary_header(const Rec& r, Cursor& c, const Line& number) {
  std::vector<Line> h;
  while (h.size() < 11) {
    const std::size_t at = h.empty() ? number.number : h.back().number;
    if (c.done()) r.fail(at, "header", "must have 11 lines before the binary data", "the end of the file");
    h.push_back(c.next());
    if (is_delimiter(h.back().text))
      r.fail(h.back().number, "header", "must have 11 lines before the binary data", "the closing '-1'");
  }
  return h;
}

void read_binary_function(const Rec& r, Cursor& c, const Line& number, File& out) {
  const BinaryLayout b = binary_layout(r, number);
  const std::vector<Line> h = binary_header(r, c, number);
  Function f = function_header(r, h);
  f.binary = true;
  const std::string_view s = c.bytes();
  const std::size_t start = c.pos(), left = s.size() - start;
  if (b.n_bytes > left)
    r.fail(number.number, "n_bytes", "must fit the " + std::to_string(left) + " bytes left in the file",
           std::to_string(b.n_bytes));
  const std::size_t expected = f.points * values_per_point(f) * static_cast<std::size_t>(f.value_bytes);
  std::size_t length = b.n_bytes, end = closing_after(s, start + length);
  if (end == kNotFound && expected != length && expected <= left && (end = closing_after(s, start + expected)) != kNotFound)
    length = expected;
  if (end == kNotFound)
    r.fail(number.number, "n_bytes", "must end the binary block right before the closing '    -1' line",
           std::to_string(b.n_bytes));
  if (length != expected)
    r.fail(h[6].number, "num_pts",
           "must match the binary block of " + std::to_string(length) + " bytes (" + std::to_string(f.value_bytes) +
               " per value, " + std::to_string(values_per_point(f)) + " values per point)",
           std::to_string(f.points));
  assign_values(r, h[6], f, decode_binary(r, s.substr(start, length), f.value_bytes, b.big_endian));
  c.skip_to(end);
  out.functions.push_back(std::move(f));
}

// ---------------------------------------------------------------------------------------------
// The file.

struct DatasetId {
  int number = 0;
  bool binary = false;
};

DatasetId dataset_id(const std::string& source, std::size_t record, const Line& l) {
  const auto t = tokens(l.text);
  const std::string where = "record " + std::to_string(record) + ": dataset number";
  if (t.empty()) fail_file(source, l.number, where + " must follow the opening '-1' line", "a blank line");
  std::string n = t[0];
  DatasetId id;
  if (n.size() > 1 && (n.back() == 'b' || n.back() == 'B')) {
    id.binary = true;
    n.pop_back();
  }
  if (!parse_int(n, id.number) || id.number <= 0)
    fail_file(source, l.number, where + " must be a positive integer", in_quotes(t[0]));
  return id;
}

// The lines of an ASCII dataset up to its closing "-1" line (consumed).
std::vector<Line> body_lines(const Rec& r, Cursor& c) {
  std::vector<Line> body;
  while (!c.done()) {
    Line l = c.next();
    if (is_delimiter(l.text)) return body;
    body.push_back(l);
  }
  r.fail(body.empty() ? r.line : body.back().number, "dataset", "must end with a '    -1' line (truncated file?)",
         "the end of the file");
}

void read_dataset(const Rec& r, int number, const std::vector<Line>& body, File& out) {
  switch (number) {
    case 151:
      read_header(r, body, out);
      break;
    case 164:
      read_units(r, body, out);
      break;
    case 15:
      read_nodes15(r, body, out);
      break;
    case 2411:
      read_nodes2411(r, body, out);
      break;
    case 55:
      read_shape(r, body, out);
      break;
    case 58:
      read_ascii_function(r, body, out);
      break;
    default:
      out.skipped.push_back(Skipped{number, false, r.record, r.line});
  }
}

}  // namespace

File parse(const std::string& bytes, const std::string& source) {
  File out;
  out.source = source;
  Cursor c(bytes);
  while (true) {
    c.skip_blank_lines();
    if (c.done()) break;
    const Line open = c.next();
    if (!is_delimiter(open.text))
      fail_file(source, open.number, "expected a '    -1' line opening a dataset",
                in_quotes(trim(Columns(open.text).text())));
    if (c.done())
      fail_file(source, open.number, "the '    -1' line must be followed by a dataset number (truncated file?)",
                "the end of the file");
    const Line number = c.next();
    const DatasetId id = dataset_id(source, out.datasets + 1, number);
    const Rec r{&source, ++out.datasets, std::to_string(id.number) + (id.binary ? "b" : ""), number.number};
    if (id.number == 58 && id.binary) {
      read_binary_function(r, c, number, out);
    } else {
      const auto body = body_lines(r, c);
      if (id.binary)
        out.skipped.push_back(Skipped{id.number, true, r.record, r.line});
      else
        read_dataset(r, id.number, body, out);
    }
  }
  if (out.datasets == 0) fail_file(source, 1, "empty, expected a '    -1' line opening a dataset", "no dataset");
  return out;
}

File read_file(const std::string& path) {
  InputFileStream in(path, "UFF file '" + path + "'");
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  check_interrupt();
  if (in.bad()) throw InputError(one_line("UFF file '" + path + "': cannot be read"));
  return parse(bytes, path);
}

bool looks_like_uff(const std::string& first_bytes) {
  std::string_view s = first_bytes;
  if (s.substr(0, 3) == "\xEF\xBB\xBF") s.remove_prefix(3);
  std::size_t i = 0;
  while (i < s.size() && is_blank_char(s[i])) ++i;
  const std::size_t e = s.find_first_of("\r\n", i);
  const std::string_view first = s.substr(i, e == std::string_view::npos ? std::string_view::npos : e - i);
  return trim(first) == "-1";
}

std::string function_type_name(int type) {
  // clang-format off
  static const char* const names[] = {
      "General", "Time Response", "Auto Spectrum", "Cross Spectrum",                            // 0-3
      "Frequency Response Function", "Transmissibility", "Coherence", "Auto Correlation",      // 4-7
      "Cross Correlation", "Power Spectral Density", "Energy Spectral Density",                // 8-10
      "Probability Density Function", "Spectrum", "Cumulative Frequency Distribution",         // 11-13
      "Peaks Valley", "Stress/Cycles", "Strain/Cycles", "Orbit", "Mode Indicator Function",    // 14-18
      "Force Pattern", "Partial Power", "Partial Coherence", "Eigenvalue", "Eigenvector",      // 19-23
      "Shock Response Spectrum", "Finite Impulse Response Filter", "Multiple Coherence",       // 24-26
      "Order Function"};                                                                       // 27
  // clang-format on
  if (type < 0 || type > 27) return "Unknown";
  return names[type];
}

std::string direction_name(int direction) {
  if (direction == 0) return "";
  if (direction < -6 || direction > 6) return "?" + std::to_string(direction);
  static const char* const axes[] = {"X", "Y", "Z", "RX", "RY", "RZ"};
  return std::string(direction > 0 ? "+" : "-") + axes[std::abs(direction) - 1];
}

std::string channel_name(const Function& f) {
  const std::string id = std::string(trim(f.id1));
  if (!id.empty() && !is_none(id)) return id;
  const std::string entity = std::string(trim(f.response_entity));
  const std::string dof = std::to_string(f.response_node) + direction_name(f.response_direction);
  if (!entity.empty() && !is_none(entity)) return entity + ":" + dof;
  if (f.response_node != 0 || f.response_direction != 0) return dof;
  return "function" + std::to_string(f.record);
}

std::vector<std::string> channel_names(const File& file) {
  std::vector<std::string> names;
  std::set<std::string> used;
  for (const Function& f : file.functions) {
    const std::string base = channel_name(f);
    std::string name = base;
    for (int k = 2; used.count(name) != 0; ++k) name = base + "#" + std::to_string(k);
    used.insert(name);
    names.push_back(name);
  }
  return names;
}

std::string ordinate_unit(const Function& f) {
  const std::string u = std::string(trim(f.ordinate.unit));
  return is_none(u) ? std::string() : u;
}

std::string abscissa_unit(const Function& f) {
  const std::string u = std::string(trim(f.abscissa.unit));
  return is_none(u) ? std::string() : u;
}

}  // namespace scoleid::io::uff
