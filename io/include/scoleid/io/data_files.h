#pragma once
// The data files that are the only bridge between the truth generator and the identifier:
//   truth.csv   header "t,<columns>", one row per sample; t strictly increasing; all finite.
//   truth.json  {"scenario", "structure", "columns":[{"name","unit","kind":"input"|"output",
//                "quantity","at","location","direction","noise_std"}], "true_parameters":{...},
//                "generator":{...}, "settings":{scenario echo}}
//   identify.json  see identify/; written through write_json_atomic.
// Every write goes to a temporary file in the same directory and is renamed into place, so a
// failed run never leaves a half-written output.
#include <istream>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace scoleid::io {

struct DataTable {
  std::vector<std::string> names;             // column names (free text), without the time column
  std::vector<double> t;                      // sample times [s]
  std::vector<std::vector<double>> columns;   // columns[j][i] = value of names[j] at t[i]
  std::string source;                         // path read from, for messages
  // Each column's unit as its file states it (a header's bracketed suffix, a UFF record), "" when
  // it states none; empty or one per column. The values are in that unit, unconverted.
  std::vector<std::string> units;
  std::string time_name = "t";                // the time column's header
  std::string time_unit;                      // its stated unit ("" = s); t is in seconds
  // Times the file does not hold but states as t0 + k·step (an LVM with X_Columns No: its Delta_X):
  // that step [s] and half a unit of its last written digit (0.000977 → 5e-7); 0 when the times are
  // read from a column. A stated sample rate within that rounding of the step replaces it
  // (time_grid.h stated_grid).
  double stated_step = 0.0, stated_step_rounding = 0.0;
  // The unit of column j ("" when none is stated).
  std::string unit(int j) const;

  // Index of a column, or -1.
  int find(const std::string& name) const;
  // Linear interpolation of column j at time tt (clamped to the ends).
  double interpolate(int j, double tt) const;
};

// How a CSV is read. The file's own dialect is detected from its header line: fields separated by
// ';' (then a decimal comma is read as a point) or a tab (likewise) where the header has one,
// else ','; fields may be double-quoted ("Acc1, x [g]"); '#' lines are comments. Column names are
// free text; a bracketed suffix ("Time [ms]", "Acc1 [g]") states a column's unit.
struct CsvOptions {
  std::string time_column;  // the time column's header; "" = the first column, whatever its name
  std::string time_unit;    // its unit when the header states none ("" = s)
};

// Throws InputError naming the file, line, column and value for: missing file, empty file,
// no time column, duplicate names, wrong field count, non-numeric or non-finite values, time not
// strictly increasing, an unknown time unit.
DataTable read_csv(const std::string& path, const CsvOptions& options = {});
// The same on text already in memory / a stream; `path` names it in messages.
DataTable read_csv_text(const std::string& text, const std::string& path, const CsvOptions& options = {});
DataTable read_csv_stream(std::istream& in, const std::string& path, const CsvOptions& options = {});

// A CSV read in chunks of rows, for a record longer than memory need hold (scole-data frf streams
// one through the Welch estimator): the header as read_csv reads it, then the rows as they come,
// each checked as read_csv checks it (field count, numbers, finite, magnitude, the time strictly
// increasing in its stated unit and in seconds). read_csv is this reader read to the end, with
// the record's sample limit.
class CsvReader {
 public:
  // Reads the header of the file at `path` (or of `in`); InputError as read_csv.
  explicit CsvReader(const std::string& path, const CsvOptions& options = {});
  CsvReader(std::istream& in, const std::string& path, const CsvOptions& options = {});
  ~CsvReader();
  CsvReader(const CsvReader&) = delete;
  CsvReader& operator=(const CsvReader&) = delete;
  // names, units, time_name, time_unit and source of the table; no rows.
  const DataTable& header() const;
  // At most max_rows more rows: t (seconds) and columns[j] (sized to header().names) replaced by
  // them. Returns the rows read, 0 at the end of the file. max_samples > 0 refuses a row beyond
  // that many in all (naming its line).
  std::size_t read(std::size_t max_rows, std::vector<double>& t, std::vector<std::vector<double>>& columns,
                   double max_samples = 0);
  // Rows read so far.
  std::size_t rows() const;

 private:
  struct State;
  std::unique_ptr<State> s_;
};
// A table held as columns in memory (a program's arrays, a DataFrame), read as read_csv reads a
// file with that header: the time column chosen by options (the first when none is named), each
// column's unit from its name's bracketed suffix, the time converted into seconds, then
// check_table. `source` names it in messages.
DataTable table_from_columns(const std::vector<std::string>& header, const std::vector<std::vector<double>>& columns,
                             const std::string& source, const CsvOptions& options = {});
// What every record must satisfy however it arrives (a file, a program's memory, Python): at
// least 2 and at most limits::kMaxSamples samples, times strictly increasing, one value per time
// in every column, names non-empty, unique and not the time column's, every value finite and of
// magnitude at most limits::kMaxMagnitude. The readers check as they read (naming the line);
// this checks a table built elsewhere, naming the source, column and sample.
void check_table(const DataTable& table);
// A field as write_csv writes a header's: quoted ("" for a quote) when it holds a separator, a quote
// or outer blanks, or starts a comment.
std::string csv_field(const std::string& name);
// 17 significant digits; atomic.
void write_csv(const std::string& path, const DataTable& table);
// The fields of one CSV line, each trimmed of blanks and double quotes ('\r' dropped); a quoted
// field keeps its separators ("a,b") and reads "" as one quote.
std::vector<std::string> split_csv_line(const std::string& line, char separator = ',');

struct ColumnMeta {
  std::string name;
  std::string unit;
  std::string kind;        // input | output
  std::string quantity;    // force | moment | displacement | rotation | velocity | acceleration | line_of_sight
  std::string at;          // beam | mast | shuttle | reflector | actuator1 | actuator2
  double location = 0.0;   // arc length s, where meaningful
  std::vector<double> direction = {0.0, 0.0, 0.0};
  double noise_std = 0.0;
};

struct TruthMeta {
  std::string scenario;
  std::string structure;
  std::vector<ColumnMeta> columns;
  std::map<std::string, double> true_parameters;
  nlohmann::json generator = nlohmann::json::object();
  nlohmann::json settings = nlohmann::json::object();
};

nlohmann::json to_json(const TruthMeta& m);
TruthMeta truth_meta_from_json(const nlohmann::json& j, const std::string& source);
TruthMeta read_truth_meta(const std::string& path);

// Reads a JSON file; InputError on a missing file or a parse error (with position).
nlohmann::json read_json(const std::string& path);
// Pretty-printed, atomic.
void write_json_atomic(const std::string& path, const nlohmann::json& j);
// Writes `text` to path atomically (temp file in the same directory + rename).
void write_text_atomic(const std::string& path, const std::string& text);
// Creates a directory (and parents); InputError if it cannot.
void ensure_directory(const std::string& dir);

}  // namespace scoleid::io
