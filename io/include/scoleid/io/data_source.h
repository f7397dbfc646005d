#pragma once
// A measured record as the identifier and the cross-check read it, whatever the file it came in
// (docs/data.md):
//   *.uff, *.unv, or a file that starts as a Universal File: the time responses (dataset 58/58b,
//       function type 1) on one time grid, each channel named by its ID line 1 (or
//       <entity>:<node><direction>), its unit from the record; any other function (FRF, spectrum,
//       PSD) is refused with its record and type named;
//   a file whose first line begins "LabVIEW Measurement": a LabVIEW Measurement file (lvm.h);
//   anything else: a CSV (data_files.h), the DAQ dialects included.
// Values stay in their file's units; each column's unit is in DataTable::units.
#include <memory>
#include <string>
#include <vector>

#include "scoleid/io/data_files.h"

namespace scoleid::io {

// The JSON that `scole-data convert` writes beside OUT.csv (OUT.json): {"format": kColumnsFormat,
// "columns": [{"name", "unit", "quantity", "node", "direction"}]}. Reading OUT.csv, read_data takes
// each column's unit from it where the header states none.
inline constexpr const char* kColumnsFormat = "scole-data columns 1";

// Whether the file at `path` is a Universal File (by its first non-blank line, "-1").
bool is_uff_file(const std::string& path);
// Whether the file at `path` is a LabVIEW Measurement file (by its first line).
bool is_lvm_file(const std::string& path);

// The record as a table. InputError naming the file (and record, line, field) on anything wrong.
DataTable read_data(const std::string& path, const CsvOptions& options = {});

// Whether read_data reads `path` as a CSV (it is no Universal, LabVIEW Measurement or TDMS file).
bool is_csv_data(const std::string& path);
// A CSV opened to be read in chunks as read_data reads it whole: the time unit and the columns'
// units (the header's, else those of the column description beside a converted file) as
// read_data's table has them.
struct CsvData {
  std::unique_ptr<CsvReader> reader;
  std::vector<std::string> units;  // one per column of reader->header().names
};
CsvData open_csv_data(const std::string& path, const CsvOptions& options = {});

// One channel of a data file, as `scole-data info` lists it.
struct Channel {
  std::string name;
  std::string unit;        // "" = not stated
  std::string quantity;    // what the file says it measures ("" = not stated)
  std::size_t samples = 0;
  double start = 0.0;      // first abscissa value
  double step = 0.0;       // abscissa increment (mean increment when uneven)
  bool even = true;
  bool time_response = true;  // false: a spectrum, FRF, ... (listed, never converted)
  std::string function;    // the UFF function type's name ("time response", "frequency response function", ...)
  std::string abscissa_unit;
  int record = 0;          // UFF record (1-based), 0 for CSV
  int node = 0;            // UFF response node, 0 when none
  std::string direction;   // "+Z" etc., "" when none
};

struct DataFileInfo {
  std::string source;
  std::string format;                // "csv" | "uff"
  std::vector<Channel> channels;
  std::vector<std::string> notes;    // header, unit system, nodes, modes, datasets skipped
};

DataFileInfo describe_data(const std::string& path, const CsvOptions& options = {});
// The channels of a table read from a file of `format` (time responses on its time grid: mean
// step, even within 1e-6 of it), without notes.
DataFileInfo describe_table(const DataTable& table, const std::string& format);

}  // namespace scoleid::io
