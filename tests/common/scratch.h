#pragma once
// A per-process scratch directory for tests that write files: temp/scoleid-test-<pid>, made on
// first use and removed with everything in it when the test process exits, so a suite run leaves
// nothing behind (a test that crashes leaves its directory for inspection).
#include <unistd.h>

#include <filesystem>
#include <string>
#include <system_error>

namespace scoleid::test {

inline const std::filesystem::path& scratch_root() {
  struct Root {
    std::filesystem::path path;
    Root() : path(std::filesystem::temp_directory_path() / ("scoleid-test-" + std::to_string(::getpid()))) {
      std::filesystem::create_directories(path);
    }
    ~Root() {
      std::error_code ec;
      std::filesystem::remove_all(path, ec);
    }
  };
  static const Root root;
  return root.path;
}

}  // namespace scoleid::test
