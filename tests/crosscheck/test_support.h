#pragma once
// What the cross-check's program tests share: run a command, read a file, a scratch directory.
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace scoleid::test {

// The exit code of `cmd` run by the shell (-1 if it did not exit).
inline int sh(const std::string& cmd) {
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// An empty directory under the temporary directory, named by `prefix`, `tag` and the process.
inline std::filesystem::path scratch(const std::string& prefix, const std::string& tag) {
  const auto d = std::filesystem::temp_directory_path() / ("scoleid-" + prefix + "-" + tag + "-" + std::to_string(::getpid()));
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

}  // namespace scoleid::test
