#pragma once
// MATLAB .mat files (version 5, readable by MATLAB, Octave and scipy.io.loadmat) through libmatio
// (Debian libmatio-dev), when the build found it: the identified plant for control design
// (scole-identify --export-model FILE.mat, docs/theory.md §10.2).
#include <string>
#include <vector>

namespace scoleid::io {

// One variable: a real matrix (rows x cols, values in column-major order, as MATLAB and Eigen store
// them), or a list of strings (a cell array of char rows).
struct MatVariable {
  std::string name;
  std::size_t rows = 0, cols = 0;
  std::vector<double> values;
  std::vector<std::string> strings;
  bool is_strings = false;
};

// Whether this build can write .mat files.
bool mat_files_supported();
// Writes the variables to `path` (a temporary file beside it, renamed into place). InputError when
// the build has no libmatio; std::runtime_error when the file cannot be written.
void write_mat_file(const std::string& path, const std::vector<MatVariable>& variables);

}  // namespace scoleid::io
