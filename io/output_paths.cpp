#include "scoleid/io/output_paths.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>

#include "scoleid/io/error.h"
#include "scoleid/io/run_directory.h"
#include "scoleid/io/validation.h"

namespace scoleid::io {

namespace fs = std::filesystem;

namespace {
fs::path normal(const std::string& p) {
  std::error_code ec;
  fs::path a = fs::weakly_canonical(fs::absolute(fs::path(p), ec), ec);
  if (ec) a = fs::absolute(fs::path(p)).lexically_normal();
  if (!a.has_filename() && a.has_parent_path()) a = a.parent_path();
  return a;
}
}  // namespace

bool same_file(const std::string& a, const std::string& b) {
  if (a.empty() || b.empty()) return false;
  std::error_code ec;
  if (fs::exists(a, ec) && fs::exists(b, ec) && fs::equivalent(a, b, ec) && !ec) return true;
  return normal(a) == normal(b);
}

bool inside(const std::string& path, const std::string& dir) {
  if (path.empty() || dir.empty()) return false;
  const fs::path p = normal(path), d = normal(dir);
  auto pi = p.begin();
  for (auto di = d.begin(); di != d.end(); ++di, ++pi)
    if (pi == p.end() || *pi != *di) return false;
  return true;
}

void check_output_file(const std::string& option, const std::string& path, const std::vector<std::string>& inputs,
                       const std::string& out_dir) {
  const std::string where = "command line: " + option + " '" + shorten(path) + "'";
  if (path.empty()) throw InputError("command line: " + option + " is empty (give a file name)");
  if (path.find('\0') != std::string::npos) throw InputError(where + ": holds a NUL character");
  for (const auto& in : inputs) {
    std::error_code ec;
    if (in.empty() || !fs::exists(in, ec)) continue;  // a built-in scenario's name is no file
    if (same_file(path, in)) throw InputError(where + ": is an input of this run (" + shorten(in) + "); it would be overwritten");
  }
  if (!out_dir.empty() && inside(path, out_dir))
    throw InputError(where + ": lies inside the output directory --out '" + shorten(out_dir) +
                     "', which the run replaces as a whole; write it elsewhere");
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw InputError(where + ": is a directory; give a file name");
  const fs::path p(path);
  const fs::path dir = p.has_parent_path() ? p.parent_path() : fs::path(".");
  if (!fs::is_directory(dir, ec)) throw InputError(where + ": directory '" + dir.string() + "' does not exist");
  // Not into a directory another run or a campaign is writing (its commit or resume would meet it).
  check_not_inside_running(path, "command line: " + option);
  if (::access(dir.c_str(), W_OK | X_OK) != 0)
    throw InputError(where + ": directory '" + dir.string() + "' is not writable (" + std::strerror(errno) + ")");
  // access() answers yes to root everywhere: a file made and removed proves the directory takes one.
  const fs::path probe = dir / (".scoleid-probe-" + std::to_string(::getpid()));
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0) throw InputError(where + ": directory '" + dir.string() + "' takes no new file (" + std::strerror(errno) + ")");
  ::close(fd);
  ::unlink(probe.c_str());
}

void check_inputs_outside(const std::string& option, const std::string& out_dir, const std::vector<std::string>& inputs) {
  for (const auto& in : inputs) {
    std::error_code ec;
    if (in.empty() || !fs::exists(in, ec)) continue;
    if (inside(in, out_dir))
      throw InputError("command line: " + option + " '" + shorten(out_dir) + "': holds an input of this run ('" + shorten(in) +
                       "'), and the run replaces the directory as a whole; move the input out or choose another " + option);
  }
}

StagedFile::StagedFile(std::string final_path, const std::string& what) : final_(std::move(final_path)) {
  const fs::path p(final_);
  const fs::path dir = p.has_parent_path() ? p.parent_path() : fs::path();
  temp_ = (dir / ("." + p.stem().string() + ".staging-" + std::to_string(::getpid()) + p.extension().string())).string();
  // Made now, so that a directory that takes no new file is refused before the work.
  const int fd = ::open(temp_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0)
    throw InputError(what + " '" + shorten(final_) + "': cannot write in directory '" + (dir.empty() ? std::string(".") : dir.string()) +
                     "' (" + std::strerror(errno) + ")");
  ::close(fd);
}

StagedFile::~StagedFile() {
  if (committed_) return;
  std::error_code ec;
  fs::remove(temp_, ec);
}

void StagedFile::commit() {
  if (committed_) return;
  if (std::rename(temp_.c_str(), final_.c_str()) != 0)
    throw std::runtime_error("cannot move '" + temp_ + "' into '" + final_ + "': " + std::strerror(errno));
  committed_ = true;
}

}  // namespace scoleid::io
