#pragma once
// Output files named on a command line (--export-model, scole-data convert --out), checked against
// the run's inputs and its output directory before any work, so that no input is ever overwritten
// and no run fails only at its end:
//   - the path is not an input (the same file, however it is spelled: a link, "./", "../x");
//   - it does not lie inside the run's output directory (which the run replaces as one unit);
//   - it is not a directory, and its directory exists and is writable.
// A refusal is an InputError naming the option and the path (exit 2, nothing written).
//
// StagedFile writes such a file under a temporary name beside it during the run and puts it in
// place with one rename after the run's outputs are committed; a run that fails or is interrupted
// leaves nothing.
#include <string>
#include <vector>

namespace scoleid::io {

// `option` names the path in messages ("--export-model"); `inputs` are the run's input files (empty
// entries and built-in scenario names, which are no files, are skipped); `out_dir` the run's
// output directory ("" for none).
void check_output_file(const std::string& option, const std::string& path, const std::vector<std::string>& inputs,
                       const std::string& out_dir = "");

// Every existing input file that lies inside the output directory `out_dir` is refused: the run
// replaces that directory as a whole (an input named like one of its outputs, q/fit.csv read with
// --out q, would be overwritten). `option` names the directory's option ("--out").
void check_inputs_outside(const std::string& option, const std::string& out_dir, const std::vector<std::string>& inputs);

// True when a and b name the same file, or the same path once made absolute and normal (for paths
// that do not exist yet).
bool same_file(const std::string& a, const std::string& b);
// True when `path` lies inside directory `dir` (or is it).
bool inside(const std::string& path, const std::string& dir);

class StagedFile {
public:
  // The temporary keeps the final name's extension (writers choose the format by it). It is
  // created at once (InputError beginning with `what`, "command line: --export-model", if the
  // directory takes no new file).
  StagedFile(std::string final_path, const std::string& what);
  ~StagedFile();  // removes the temporary unless committed
  StagedFile(const StagedFile&) = delete;
  StagedFile& operator=(const StagedFile&) = delete;
  const std::string& path() const { return temp_; }
  // Renames the temporary onto the final path (throws std::runtime_error if that fails).
  void commit();

private:
  std::string final_, temp_;
  bool committed_ = false;
};

}  // namespace scoleid::io
