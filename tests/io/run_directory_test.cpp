// A run's outputs as one unit (io/run_directory.h): a new directory appears whole; an earlier
// run is replaced whole; a run that fails or is interrupted changes nothing and leaves no
// staging directory; a directory holding anything else is refused before any work.
#include "scoleid/io/run_directory.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "scoleid/io/data_files.h"
#include "scoleid/io/error.h"
#include "scoleid/io/interrupt.h"

namespace fs = std::filesystem;
using namespace scoleid::io;

namespace {
class RunDirectoryTest : public ::testing::Test {
protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() / ("scoleid-rundir-" + std::to_string(::getpid()) + "-" +
                                         ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(root_);
    fs::create_directories(root_);
  }
  void TearDown() override { fs::remove_all(root_); }
  static std::string slurp(const fs::path& p) {
    std::ifstream in(p);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  }
  // root_/run as an earlier run (or a user) left it: one file `name` holding `text`.
  fs::path existing_run(const std::string& name, const std::string& text) {
    const fs::path out = root_ / "run";
    fs::create_directories(out);
    write_text_atomic((out / name).string(), text);
    return out;
  }
  // Names in root_ other than `keep`: staging directories left behind would show here.
  std::vector<std::string> leftovers(const std::string& keep) const {
    std::vector<std::string> out;
    for (const auto& e : fs::directory_iterator(root_))
      if (e.path().filename() != keep) out.push_back(e.path().filename().string());
    return out;
  }
  const std::vector<std::string> owned_{"a.csv", "b.json"};
  fs::path root_;
};
}  // namespace

TEST_F(RunDirectoryTest, NewDirectoryAppearsOnlyAtCommit) {
  const fs::path out = root_ / "sub" / "run";
  {
    RunDirectory d(out.string(), owned_, "test");
    write_text_atomic(d.path("a.csv"), "new a\n");
    write_text_atomic(d.path("b.json"), "new b\n");
    EXPECT_FALSE(fs::exists(out)) << "visible before commit";
    d.commit();
  }
  EXPECT_EQ(slurp(out / "a.csv"), "new a\n");
  EXPECT_EQ(slurp(out / "b.json"), "new b\n");
  EXPECT_TRUE(leftovers("sub").empty());
  EXPECT_EQ(fs::directory_iterator(root_ / "sub")->path().filename(), "run");
}

TEST_F(RunDirectoryTest, EarlierRunIsReplacedWhole) {
  const fs::path out = existing_run("a.csv", "old a\n");
  write_text_atomic((out / "b.json").string(), "old b\n");
  {
    RunDirectory d(out.string(), owned_, "test");
    write_text_atomic(d.path("a.csv"), "new a\n");  // this run writes no b.json
    d.commit();
  }
  EXPECT_EQ(slurp(out / "a.csv"), "new a\n");
  EXPECT_FALSE(fs::exists(out / "b.json")) << "a file of the earlier run survived beside the new one";
  EXPECT_TRUE(leftovers("run").empty());
}

TEST_F(RunDirectoryTest, FailedRunLeavesTheEarlierRunUntouched) {
  const fs::path out = existing_run("a.csv", "old a\n");
  try {
    RunDirectory d(out.string(), owned_, "test");
    write_text_atomic(d.path("a.csv"), "half");
    throw std::runtime_error("disk full");
  } catch (const std::runtime_error&) {
  }
  EXPECT_EQ(slurp(out / "a.csv"), "old a\n");
  EXPECT_TRUE(leftovers("run").empty()) << "staging directory left behind";
}

TEST_F(RunDirectoryTest, InterruptedRunDoesNotCommit) {
  install_interrupt_handlers();
  const fs::path out = root_ / "run";
  RunDirectory d(out.string(), owned_, "test");
  write_text_atomic(d.path("a.csv"), "x");
  std::raise(SIGTERM);
  try {
    d.commit();
    ADD_FAILURE() << "committed after SIGTERM";
  } catch (const Interrupted& e) {
    EXPECT_EQ(e.exit_code(), 143);
  }
  clear_interrupt();
  EXPECT_FALSE(fs::exists(out));
}

TEST_F(RunDirectoryTest, ForeignFilesAndNonDirectoriesAreRefused) {
  const fs::path out = existing_run("notes.txt", "mine\n");
  try {
    RunDirectory d(out.string(), owned_, "test");
    ADD_FAILURE() << "accepted a directory with a user file";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("notes.txt"), std::string::npos) << e.what();
  }
  EXPECT_EQ(slurp(out / "notes.txt"), "mine\n");
  write_text_atomic((root_ / "file").string(), "x");
  EXPECT_THROW(RunDirectory((root_ / "file").string(), owned_, "test"), InputError);
  EXPECT_THROW(RunDirectory((root_ / "file" / "below").string(), owned_, "test"), InputError);
  EXPECT_TRUE(leftovers("run").size() == 1u);  // just "file"
}

TEST_F(RunDirectoryTest, ASymbolicLinkIsRefusedBeforeAnyWorkDanglingOrNot) {
  // The commit renames onto the path: a dangling link would fail only at the end of the run, a
  // link to a directory would be replaced by the run. Both refused at once, naming the path.
  fs::create_symlink(root_ / "nowhere", root_ / "dangling");
  fs::create_directories(root_ / "real");
  fs::create_symlink(root_ / "real", root_ / "link");
  for (const char* name : {"dangling", "link"}) {
    try {
      RunDirectory d((root_ / name).string(), owned_, "test");
      ADD_FAILURE() << name << " accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("symbolic link"), std::string::npos) << e.what();
    }
  }
  EXPECT_TRUE(fs::is_symlink(root_ / "link"));
  EXPECT_FALSE(fs::exists(root_ / "nowhere"));
}

TEST_F(RunDirectoryTest, QuotesAndSemicolonsInTheNameAreJustCharacters) {
  const fs::path out = root_ / "mast's runs; touch pwned; '";
  {
    RunDirectory d(out.string(), owned_, "test");
    write_text_atomic(d.path("a.csv"), "a\n");
    d.commit();
  }
  EXPECT_EQ(slurp(out / "a.csv"), "a\n");
  EXPECT_FALSE(fs::exists(root_ / "pwned"));
}

TEST_F(RunDirectoryTest, KeepEarlierOutputsReplacesOnlyWhatThisRunWrote) {
  // Commands sharing one output directory (scole-crosscheck's verbs): each replaces its own
  // outputs and keeps the others', owned directories included.
  const fs::path out = root_ / "run";
  const std::vector<std::string> owned{"a.csv", "b.json", "sub"};
  fs::create_directories(out / "sub");
  write_text_atomic((out / "a.csv").string(), "old a\n");
  write_text_atomic((out / "b.json").string(), "old b\n");
  write_text_atomic((out / "sub" / "c.csv").string(), "old c\n");
  {
    RunDirectory d(out.string(), owned, "test");
    write_text_atomic(d.path("a.csv"), "new a\n");
    d.keep_earlier_outputs();
    d.commit();
  }
  EXPECT_EQ(slurp(out / "a.csv"), "new a\n");
  EXPECT_EQ(slurp(out / "b.json"), "old b\n");
  EXPECT_EQ(slurp(out / "sub" / "c.csv"), "old c\n");
  EXPECT_TRUE(leftovers("run").empty());
  // Without keep_earlier_outputs the earlier run is replaced whole, as before.
  {
    RunDirectory d(out.string(), owned, "test");
    write_text_atomic(d.path("b.json"), "newer b\n");
    d.commit();
  }
  EXPECT_FALSE(fs::exists(out / "a.csv"));
  EXPECT_FALSE(fs::exists(out / "sub"));
  EXPECT_EQ(slurp(out / "b.json"), "newer b\n");
}
