#pragma once
// What the tests that run the programs from the shell share: quoting, reading and writing files,
// a scratch directory, and a run's exit code with its standard output and error.
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace scoleid::test {

// `s` as one word of a POSIX shell command line.
inline std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// A file's bytes ("" if it cannot be read).
inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Writes `text` to `p` (replacing it); returns the path. Throws if it cannot.
inline std::string write_file(const std::filesystem::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out << text;
  if (!out.good()) throw std::runtime_error("cannot write " + p.string());
  return p.string();
}

// The exit code of `cmd` run by the shell (-1 if it did not exit).
inline int sh(const std::string& cmd) {
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// An empty directory under the temporary directory, named by `prefix`, `tag` and the process.
inline std::filesystem::path scratch(const std::string& prefix, const std::string& tag) {
  const auto d = std::filesystem::temp_directory_path() / ("scoleid-" + prefix + "-" + tag + "-" + std::to_string(::getpid()));
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

struct CommandResult {
  int code = -1;  // the exit code, -1 if the program did not exit (a signal)
  std::string out, err;
};

// Runs `exe args…` from inside `dir` (so a command smuggled through a name would leave its marker
// there), stdin from /dev/null; stdout through a pipe, stderr through dir/stderr.txt.
inline CommandResult run_command(const std::string& exe, const std::vector<std::string>& args,
                                 const std::filesystem::path& dir) {
  const std::filesystem::path err_file = dir / "stderr.txt";
  std::string cmd = "cd " + shell_quote(dir.string()) + " && " + shell_quote(exe);
  for (const auto& a : args) cmd += " " + shell_quote(a);
  cmd += " 2> " + shell_quote(err_file.string()) + " < /dev/null";
  CommandResult r;
  FILE* pipe = ::popen(cmd.c_str(), "r");
  if (!pipe) {
    r.err = "popen failed for: " + cmd;
    return r;
  }
  char buf[4096];
  std::size_t n = 0;
  while ((n = std::fread(buf, 1, sizeof buf, pipe)) > 0) r.out.append(buf, n);
  const int status = ::pclose(pipe);
  r.code = (status != -1 && WIFEXITED(status)) ? WEXITSTATUS(status) : -1;
  r.err = slurp(err_file);
  return r;
}

}  // namespace scoleid::test
