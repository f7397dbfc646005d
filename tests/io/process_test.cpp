// Helper programs (io/process.h): results in the order given, a program that is not installed
// said so, and never more running at once than the cap.
#include "scoleid/io/process.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace fs = std::filesystem;
using scoleid::io::run_programs;

namespace {
class ProcessTest : public ::testing::Test {
protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("scoleid-process-" + std::to_string(::getpid()) + "-" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};
}  // namespace

TEST_F(ProcessTest, ResultsComeInOrderWithExitCodesAndMissingPrograms) {
  const auto r = run_programs({{"sh", "-c", "exit 3"}, {"scoleid-no-such-program"}, {"sh", "-c", "exit 0"}}, dir_.string());
  ASSERT_EQ(r.size(), 3u);
  EXPECT_TRUE(r[0].started);
  EXPECT_EQ(r[0].exit_code, 3);
  EXPECT_FALSE(r[1].started);
  EXPECT_FALSE(r[1].ok());
  EXPECT_TRUE(r[2].ok());
}

// Each program writes "+" when it starts and "-" when it ends to one log (appends are atomic for
// short writes); the running count read back from the log never exceeds the cap, and with more
// programs than the cap more than one runs at a time (they do run side by side).
TEST_F(ProcessTest, NeverMoreRunningThanTheCap) {
  const std::string step = "echo + >> log; sleep 0.2; echo - >> log";
  for (const std::size_t cap : {1u, 2u, 3u}) {
    fs::remove(dir_ / "log");
    std::vector<std::vector<std::string>> argvs(7, {"sh", "-c", step});
    const auto r = run_programs(argvs, dir_.string(), cap);
    for (const auto& x : r) EXPECT_TRUE(x.ok());
    std::ifstream in(dir_ / "log");
    std::string line;
    int running = 0, most = 0, starts = 0;
    while (std::getline(in, line)) {
      running += line == "+" ? 1 : -1;
      starts += line == "+";
      most = std::max(most, running);
    }
    EXPECT_EQ(starts, 7);
    EXPECT_EQ(running, 0);
    EXPECT_LE(most, static_cast<int>(cap)) << "cap " << cap;
    if (cap > 1) {
      EXPECT_GT(most, 1) << "cap " << cap;  // side by side
    }
  }
}
