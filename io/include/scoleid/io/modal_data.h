#pragma once
// The measured-modes file (docs/theory.md §6.6): natural frequencies, optionally
// damping ratios and mode shapes at named stations, one row per measured mode, as an
// experimental modal analysis reports them.
//
//   mode,frequency_hz,frequency_std_hz[,damping_ratio,damping_std][,shape_std,<station>,<station>,...]
//
//   mode              label, a positive integer, strictly increasing down the file
//   frequency_hz      natural frequency f > 0 [Hz]; frequency_std_hz > 0 its standard deviation
//   damping_ratio     modal damping ratio ζ >= 0 and damping_std > 0 its standard deviation
//                     (optional; both columns or neither)
//   <station>         the mode's amplitude at a sensor of the scenario (its name; a displacement,
//                     rotation or line-of-sight sensor, i.e. a row on u): the shape. Only its
//                     direction matters (scale and sign are arbitrary); optional.
//   shape_std         standard deviation of each component of the unit-normalised shape (> 0);
//                     required when there are station columns
// Columns are recognised by name in any order; every column whose name is none of the above is a
// station. '#' starts a comment line; blank lines are skipped; every value finite. Errors are
// io::InputError, one line naming the file, the line, the column and the value.
// io does not depend on Eigen: shapes are std::vector<double>.
#include <cmath>
#include <string>
#include <vector>

namespace scoleid::io {

struct ModalData {
  std::vector<std::string> stations;  // station (sensor) names, file order
  struct Mode {
    int label = 0;
    double frequency_hz = NAN, frequency_std_hz = NAN;
    double damping_ratio = NAN, damping_std = NAN;  // NaN without damping data
    std::vector<double> shape;                      // one value per station (empty without shapes)
    double shape_std = NAN;                         // NaN without shapes
  };
  std::vector<Mode> modes;
  std::string source;  // file read from, or a description, for messages

  // Damping data: every mode carries damping_ratio and damping_std (and there is a mode).
  bool has_damping() const;
  // Shape data: there are station columns.
  bool has_shapes() const { return !stations.empty(); }
};

// Reads the file. InputError for: a missing or empty file, a header without mode, frequency_hz
// or frequency_std_hz, an empty or duplicate column name, only one of damping_ratio/damping_std,
// stations without shape_std (or shape_std without stations), a row with the wrong number of
// fields, a value that is not a number or not finite, a label that is not a positive integer or
// not increasing, frequency_hz <= 0, a standard deviation <= 0, damping_ratio < 0, no modes.
ModalData read_modal_data(const std::string& path);
// The same on text in memory; `source` names it in messages.
ModalData read_modal_data_text(const std::string& text, const std::string& source);
// The checks of the reader on data built in memory (InputError naming d.source, the mode's label
// and the field): station names non-empty and unique, one shape value per station, everything
// else as in the file.
void validate_modal_data(const ModalData& d);
// Writes the file in the column order above, 17 significant digits, atomically (temporary file in
// the same directory, then renamed). Validates first (InputError).
void write_modal_data(const std::string& path, const ModalData& d);

}  // namespace scoleid::io
