// A run's outputs as one unit (io/run_directory.h): a new directory appears whole; an earlier
// run is replaced whole; a run that fails or is interrupted changes nothing and leaves no
// staging directory; a directory holding anything else is refused before any work.
#include "scoleid/io/run_directory.h"
#include "scoleid/io/output_paths.h"

#include <gtest/gtest.h>
#include <fcntl.h>
#include <sys/file.h>
#include <sys/wait.h>
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

// One run per directory at a time, and none inside another's: the second is refused up front,
// naming the run that holds the directory, and the lock goes with the run that held it.
TEST_F(RunDirectoryTest, ASecondRunIntoTheSameOrANestedDirectoryIsRefusedWhileTheFirstRuns) {
  const fs::path out = root_ / "run";
  {
    RunDirectory first(out.string(), owned_, "first");
    std::string msg;
    try {
      RunDirectory second(out.string(), owned_, "second");
    } catch (const InputError& e) {
      msg = e.what();
    }
    EXPECT_NE(msg.find("another run (first (pid " + std::to_string(::getpid()) + ")) is writing it"), std::string::npos) << msg;
    msg.clear();
    try {
      RunDirectory inner((out / "inner").string(), owned_, "inner");
    } catch (const InputError& e) {
      msg = e.what();
    }
    EXPECT_NE(msg.find("lies inside"), std::string::npos) << msg;
    write_text_atomic(first.path("a.csv"), "t\n");
    first.commit();
  }
  EXPECT_TRUE(fs::is_regular_file(out / "a.csv"));
  // Released: the next run may use it, and no lock file is left beside it.
  EXPECT_NO_THROW(RunDirectory again(out.string(), owned_, "again"));
  EXPECT_EQ(leftovers("run"), std::vector<std::string>{});
}

TEST_F(RunDirectoryTest, ARunInsideTheTargetRefusesTheOuterRunAndAKilledRunsLockIsNoObstacle) {
  const fs::path out = root_ / "run";
  {
    RunDirectory inner((out / "inner").string(), owned_, "inner");
    std::string msg;
    try {
      RunDirectory outer(out.string(), owned_, "outer");
    } catch (const InputError& e) {
      msg = e.what();
    }
    EXPECT_NE(msg.find("is writing 'inner' inside it"), std::string::npos) << msg;
  }
  // A lock file nobody holds (a run killed with SIGKILL) is stale: ignored.
  fs::remove_all(out);
  fs::create_directories(out);
  write_text_atomic((out / ".inner.lock").string(), "inner (pid 1)\n");
  write_text_atomic((root_ / ".run.lock").string(), "someone (pid 1)\n");
  EXPECT_NO_THROW(RunDirectory outer(out.string(), owned_, "outer"));
}

// A run holds its lock until it ends however it ends: a refusal after the lock releases it.
TEST_F(RunDirectoryTest, ARefusedRunReleasesItsLock) {
  const fs::path out = existing_run("foreign.txt", "mine");
  EXPECT_THROW(RunDirectory r(out.string(), owned_, "x"), InputError);
  EXPECT_FALSE(fs::exists(root_ / ".run.lock"));
}

// A directory the user may not write is not replaced by one they may (the commit's rename only
// needs the parent writable). Needs a user without root's pass: run as nobody when the test is
// root, else as the user.
TEST_F(RunDirectoryTest, AnUnwritableTargetIsRefusedNotReplaced) {
  const fs::path parent = root_ / "shared";
  fs::create_directories(parent / "out");
  fs::permissions(parent, fs::perms::all);  // 0777: anyone may create beside it
  fs::permissions(parent / "out", fs::perms::owner_read | fs::perms::owner_exec | fs::perms::group_read |
                                      fs::perms::group_exec | fs::perms::others_read | fs::perms::others_exec);
  fs::permissions(root_, fs::perms::all);
  const pid_t pid = ::fork();
  if (pid == 0) {
    if (::geteuid() == 0 && ::setuid(65534) != 0) ::_exit(3);
    try {
      RunDirectory r((parent / "out").string(), owned_, "x");
    } catch (const InputError& e) {
      ::_exit(std::string(e.what()).find("is not writable") != std::string::npos ? 0 : 4);
    } catch (...) {
      ::_exit(5);
    }
    ::_exit(6);
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "3: no setuid, 4: another message, 6: accepted";
  EXPECT_TRUE(fs::is_directory(parent / "out"));
}

// A campaign holds its lock inside its directory (DIR/.lock, crosscheck/campaign_runner.cpp): a run
// into DIR/x from another process is refused while it is held, and accepted once the process says
// it works for that campaign (its truths, its MPI workers) or once the lock is gone.
TEST_F(RunDirectoryTest, ARunInsideARunningCampaignIsRefusedUnlessThisProcessWorksForIt) {
  const fs::path cam = root_ / "cam";
  fs::create_directories(cam / "truths");
  const int fd = ::open((cam / ".lock").c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::flock(fd, LOCK_EX | LOCK_NB), 0);
  fs::create_directory_symlink(cam / "truths", root_ / "link");
  for (const fs::path target : {cam / "x", cam / "truths" / "p1", cam / "a" / "b" / "c", root_ / "link" / "evil"}) {
    try {
      RunDirectory d(target.string(), {"a.txt"}, "test");
      ADD_FAILURE() << "a run into " << target << " inside a running campaign was accepted";
    } catch (const InputError& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find("lies inside '" + cam.string() + "', which a campaign run is writing"), std::string::npos) << msg;
    }
    EXPECT_FALSE(fs::exists(target));
    EXPECT_FALSE(fs::exists(cam / "a")) << "a refused run made directories inside the campaign's";
    // Refused, it holds no lock of its own.
    EXPECT_FALSE(fs::exists(target.parent_path() / ("." + target.filename().string() + ".lock")));
  }
  // The shared check says the same for any other writer (a campaign inside a campaign).
  EXPECT_THROW(check_not_inside_running((cam / "inner").string(), "campaign output directory"), InputError);
  // And of a single output file (--export-model, scole-data convert -o), naming the option.
  try {
    check_output_file("--export-model", (cam / "m.json").string(), {});
    ADD_FAILURE() << "a single output file inside a running campaign was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("command line: --export-model '" + (cam / "m.json").string() + "': lies inside"), std::string::npos)
        << e.what();
  }
  EXPECT_FALSE(fs::exists(cam / "m.json"));
  // The lock released: accepted.
  ::close(fd);
  {
    RunDirectory d((cam / "x").string(), {"a.txt"}, "test");
    write_text_atomic(d.path("a.txt"), "1");
    d.commit();
  }
  EXPECT_EQ(slurp(cam / "x" / "a.txt"), "1");
  // Held again, by the campaign this process works for: its own runs inside are accepted.
  const int fd2 = ::open((cam / ".lock").c_str(), O_RDWR | O_CLOEXEC);
  ASSERT_GE(fd2, 0);
  ASSERT_EQ(::flock(fd2, LOCK_EX | LOCK_NB), 0);
  register_campaign_directory(cam.string());
  {
    RunDirectory d((cam / "truths" / "p1").string(), {"a.txt"}, "test");
    write_text_atomic(d.path("a.txt"), "2");
    d.commit();
  }
  EXPECT_EQ(slurp(cam / "truths" / "p1" / "a.txt"), "2");
  ::close(fd2);
}
