#pragma once
// A run's outputs as one unit: all of them or none.
//
// The program writes every output into a staging directory created beside the target
// (".<name>.staging-XXXXXX" in the same parent, so on the same file system) and commit() puts the
// whole directory in place with one rename — renameat2(RENAME_EXCHANGE) when the target already
// exists, so readers see the earlier run or the new one, never a mixture — and then deletes the
// earlier run. A run that fails, throws, or is interrupted (interrupt.h) never commits; the
// destructor removes the staging directory and the target is left exactly as it was.
//
// One run at a time per directory, and none inside another's: the run holds PARENT/.NAME.lock
// (flock; the file holds the program and pid, and is removed at the end) from the constructor to
// the destructor, and a run whose target lies inside a directory whose lock is held, or a
// directory holding a held lock, is refused up front (InputError naming the other run). A
// campaign (scole-crosscheck campaign) holds its lock inside its directory, DIR/.lock; a run inside
// DIR is refused too while that lock is held, unless this process works for that campaign
// (register_campaign_directory: the campaign's own truths, its MPI workers).
//
// The target may be new, empty, or hold an earlier run of the same program (only files from
// `owned`; an owned name may be a file or a directory). Anything else in it is refused up front, so no user file is ever replaced. The
// constructor also proves the parent is writable, before any work is done.
#include <filesystem>
#include <string>
#include <vector>

namespace scoleid::io {

// Throws InputError ("<what> '<target>': lies inside '<dir>', which another run ... is writing")
// when `target` lies inside a directory a RunDirectory or a campaign of another process holds.
void check_not_inside_running(const std::string& target, const std::string& what);
// This process works for the campaign writing `dir` (its lock DIR/.lock is its own): runs inside
// it are not refused by the check above.
void register_campaign_directory(const std::string& dir);

class RunDirectory {
public:
  // `program` names the caller in messages; `owned` lists the file names its runs write.
  // Throws InputError naming the directory if it cannot be used.
  RunDirectory(const std::string& target, std::vector<std::string> owned, const std::string& program);
  ~RunDirectory();
  RunDirectory(const RunDirectory&) = delete;
  RunDirectory& operator=(const RunDirectory&) = delete;

  // Where to write output `name` (one of `owned`) during the run.
  std::string path(const std::string& name) const;
  const std::string& staging() const { return staging_; }
  const std::string& target() const { return target_; }
  // Programs whose commands each write part of a shared output directory: before commit(), the
  // earlier run's entries that this run did not write are carried into the staging area (hard
  // links, or copies across file systems), so committing replaces only what this run produced.
  void keep_earlier_outputs();
  // Puts the staged outputs in place as one unit. Checks for an interrupt first (then nothing is
  // committed). Throws std::runtime_error if the file system refuses.
  void commit();
  bool committed() const { return committed_; }

  // Whether another open file description holds a flock on `lock`, and what its file says of the
  // holder ("another program" when nothing).
  static bool lock_held(const std::filesystem::path& lock);
  static std::string lock_holder(const std::filesystem::path& lock);

private:
  void lock(const std::filesystem::path& target);
  void release_lock();
  // The target's contents and the staging directory (the constructor's work after the lock).
  void check_target(const std::filesystem::path& target, const std::string& given, const std::string& program);

  std::string target_, staging_, program_, lock_path_;
  int lock_fd_ = -1;
  std::vector<std::string> owned_;
  bool committed_ = false;
};

}  // namespace scoleid::io
