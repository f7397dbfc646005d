#include "scoleid/io/run_directory.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <stdio.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>

#include "scoleid/io/error.h"
#include "scoleid/io/interrupt.h"

namespace scoleid::io {

namespace fs = std::filesystem;

namespace {
bool is_lock_name(const std::string& n) { return n.size() > 6 && n[0] == '.' && n.compare(n.size() - 5, 5, ".lock") == 0; }
// The lock of directory d: d's parent/.NAME.lock.
fs::path lock_of(const fs::path& d) { return d.parent_path() / ("." + d.filename().string() + ".lock"); }
// The campaign directories this process works for (register_campaign_directory).
std::vector<fs::path>& own_campaigns() {
  static std::vector<fs::path> dirs;
  return dirs;
}
fs::path normal_absolute(const fs::path& p) {
  std::error_code ec;
  fs::path a = fs::absolute(p, ec).lexically_normal();
  if (!a.has_filename() && a.has_parent_path()) a = a.parent_path();
  return a;
}
}  // namespace

void register_campaign_directory(const std::string& dir) { own_campaigns().push_back(normal_absolute(dir)); }

void check_not_inside_running(const std::string& target, const std::string& what) {
  // The path as spelled and as resolved (a symbolic link to a directory inside a campaign's).
  std::vector<fs::path> paths{normal_absolute(target)};
  std::error_code ec;
  const fs::path resolved = fs::weakly_canonical(paths.front(), ec);
  if (!ec && resolved != paths.front()) paths.push_back(resolved);
  for (const fs::path& t : paths)
  for (fs::path d = t.parent_path(); d.has_relative_path() && d.has_filename(); d = d.parent_path()) {
    const fs::path l = lock_of(d);
    if (RunDirectory::lock_held(l))
      throw InputError(what + " '" + target + "': lies inside '" + d.string() + "', which another run (" + RunDirectory::lock_holder(l) +
                       ") is writing; wait for it to finish or choose another directory");
    const auto& own = own_campaigns();
    if (std::find(own.begin(), own.end(), d) == own.end() && RunDirectory::lock_held(d / ".lock"))
      throw InputError(what + " '" + target + "': lies inside '" + d.string() +
                       "', which a campaign run is writing; wait for it to finish or choose another directory");
  }
}

RunDirectory::RunDirectory(const std::string& target, std::vector<std::string> owned, const std::string& program)
    : program_(program), owned_(std::move(owned)) {
  if (target.empty()) throw InputError("output directory must not be empty (give one, or leave the option out)");
  std::error_code ec;
  fs::path t = fs::absolute(fs::path(target), ec).lexically_normal();
  if (!t.has_filename() && t.has_parent_path()) t = t.parent_path();  // "dir/" -> "dir"
  if (ec || t == t.root_path() || t.filename() == "." || t.filename() == "..")
    throw InputError("output directory '" + target + "': must name a directory below an existing path");
  target_ = t.string();
  const fs::path parent = t.parent_path();
  // A symbolic link is not followed: the commit renames the staged run onto the path, which would
  // replace the link (or fail on a dangling one, after all the work).
  if (fs::is_symlink(fs::symlink_status(t, ec)))
    throw InputError("output directory '" + target + "': is a symbolic link" +
                     (fs::exists(t, ec) ? std::string() : std::string(" to nothing")) +
                     "; give the directory itself");
  // Refused before anything is made: a run inside another's directory creates no directory there.
  check_not_inside_running(target_, "output directory");
  fs::create_directories(parent, ec);
  if (ec || !fs::is_directory(parent))
    throw InputError("output directory '" + target + "': its parent cannot be created (" +
                     (ec ? ec.message() : std::string("not a directory")) + ")");
  lock(t);
  try {
    check_target(t, target, program);
  } catch (...) {
    release_lock();
    throw;
  }
}

void RunDirectory::check_target(const fs::path& t, const std::string& target, const std::string& program) {
  std::error_code ec;
  const fs::path parent = t.parent_path();
  const auto st = fs::status(t, ec);
  if (fs::exists(st)) {
    if (!fs::is_directory(st)) throw InputError("output directory '" + target + "': exists and is not a directory");
    // The run replaces the directory: one the user may not write is not replaced either.
    if (::access(t.c_str(), W_OK | X_OK) != 0)
      throw InputError("output directory '" + target + "': is not writable (" + std::strerror(errno) + ")");
    std::vector<std::string> foreign;
    for (const auto& e : fs::directory_iterator(t, ec)) {
      const std::string n = e.path().filename().string();
      if (std::find(owned_.begin(), owned_.end(), n) != owned_.end() && (e.is_regular_file() || e.is_directory()))
        continue;
      if (n.find(".tmp.") != std::string::npos) continue;  // temporary file of an older version
      if (is_lock_name(n)) {
        if (lock_held(e.path()))
          throw InputError("output directory '" + target + "': another run (" + lock_holder(e.path()) + ") is writing '" +
                           n.substr(1, n.size() - 6) + "' inside it; wait for it to finish or choose another directory");
        continue;  // left by a run that was killed
      }
      foreign.push_back(n);
    }
    if (ec) throw InputError("output directory '" + target + "': cannot be read (" + ec.message() + ")");
    if (!foreign.empty()) {
      std::sort(foreign.begin(), foreign.end());
      std::string list;
      for (std::size_t i = 0; i < foreign.size() && i < 3; ++i) list += (i ? ", " : "") + foreign[i];
      if (foreign.size() > 3) list += ", ...";
      throw InputError("output directory '" + target + "': holds files that are not outputs of " + program + " (" +
                       list + "); give a new or empty directory, or one holding only an earlier run's outputs");
    }
  }
  std::string tmpl = (parent / ("." + t.filename().string() + ".staging-XXXXXX")).string();
  std::vector<char> buf(tmpl.begin(), tmpl.end());
  buf.push_back('\0');
  if (!::mkdtemp(buf.data()))
    throw InputError("output directory '" + target + "': cannot write in '" + parent.string() + "' (" +
                     std::strerror(errno) + ")");
  staging_ = buf.data();
  // mkdtemp makes it 0700; the outputs' directory gets the mode any new directory would.
  const mode_t mask = ::umask(0);
  ::umask(mask);
  ::chmod(staging_.c_str(), 0777 & ~mask);
}

RunDirectory::~RunDirectory() {
  std::error_code ec;
  if (!committed_ && !staging_.empty()) fs::remove_all(staging_, ec);
  release_lock();
}

void RunDirectory::release_lock() {
  if (lock_fd_ < 0) return;
  ::unlink(lock_path_.c_str());  // while held: a run that opened it meanwhile finds the path gone and retries
  ::close(lock_fd_);
  lock_fd_ = -1;
}


bool RunDirectory::lock_held(const fs::path& lock) {
  const int fd = ::open(lock.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return false;
  const bool held = ::flock(fd, LOCK_SH | LOCK_NB) != 0 && errno == EWOULDBLOCK;
  ::close(fd);
  return held;
}

std::string RunDirectory::lock_holder(const fs::path& lock) {
  std::string who;
  if (FILE* f = std::fopen(lock.c_str(), "r")) {
    char buf[256] = {0};
    if (std::fgets(buf, sizeof buf, f)) who = buf;
    std::fclose(f);
  }
  while (!who.empty() && (who.back() == '\n' || who.back() == '\r')) who.pop_back();
  return who.empty() ? std::string("another program") : who;
}

void RunDirectory::lock(const fs::path& t) {
  lock_path_ = lock_of(t).string();
  // open + flock, then make sure the path still names the locked file (a finishing run unlinks
  // its lock while holding it; a waiter that opened the old file retries on the new one).
  for (int attempt = 0;; ++attempt) {
    const int fd = ::open(lock_path_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0)
      throw InputError("output directory '" + target_ + "': cannot write in '" + t.parent_path().string() + "' (" +
                       std::strerror(errno) + ")");
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
      ::close(fd);
      throw InputError("output directory '" + target_ + "': another run (" + lock_holder(lock_path_) +
                       ") is writing it; wait for it to finish or choose another directory");
    }
    struct stat a {}, b {};
    if (::fstat(fd, &a) == 0 && ::stat(lock_path_.c_str(), &b) == 0 && a.st_ino == b.st_ino && a.st_dev == b.st_dev) {
      lock_fd_ = fd;
      break;
    }
    ::close(fd);
    if (attempt > 100) throw InputError("output directory '" + target_ + "': its lock '" + lock_path_ + "' keeps changing");
  }
  const std::string who = program_ + " (pid " + std::to_string(::getpid()) + ")\n";
  if (::ftruncate(lock_fd_, 0) == 0 && ::write(lock_fd_, who.data(), who.size()) < 0) {
  }
  // Nor inside a directory another run is writing (its commit would replace this run's outputs),
  // nor inside a campaign's that this process does not work for. Refused, the lock is let go (the
  // constructor throws: no destructor runs, and a long-lived caller, Python, would keep it).
  try {
    check_not_inside_running(target_, "output directory");
  } catch (...) {
    release_lock();
    throw;
  }
}

std::string RunDirectory::path(const std::string& name) const { return (fs::path(staging_) / name).string(); }

void RunDirectory::keep_earlier_outputs() {
  std::error_code ec;
  if (!fs::is_directory(target_, ec)) return;
  for (const auto& e : fs::directory_iterator(target_, ec)) {
    const fs::path name = e.path().filename();
    if (std::find(owned_.begin(), owned_.end(), name.string()) == owned_.end()) continue;
    const fs::path dest = fs::path(staging_) / name;
    if (fs::exists(dest)) continue;  // rewritten by this run
    std::error_code cec;
    fs::copy(e.path(), dest, fs::copy_options::recursive | fs::copy_options::create_hard_links, cec);
    if (cec) {
      fs::remove_all(dest, cec);
      fs::copy(e.path(), dest, fs::copy_options::recursive, cec);
    }
    if (cec)
      throw std::runtime_error("cannot keep '" + e.path().string() + "' of the earlier run: " + cec.message());
  }
}

void RunDirectory::commit() {
  if (committed_) return;
  check_interrupt();
  std::error_code ec;
  if (!fs::exists(target_, ec)) {
    if (::rename(staging_.c_str(), target_.c_str()) != 0)
      throw std::runtime_error("cannot move the outputs into '" + target_ + "': " + std::strerror(errno));
    committed_ = true;
    return;
  }
  // The target exists (empty or an earlier run): swap the two directories in one step, then
  // remove the earlier run, which now sits under the staging name.
  if (::renameat2(AT_FDCWD, staging_.c_str(), AT_FDCWD, target_.c_str(), RENAME_EXCHANGE) != 0) {
    if (errno != EINVAL && errno != ENOSYS && errno != ENOTSUP)
      throw std::runtime_error("cannot move the outputs into '" + target_ + "': " + std::strerror(errno));
    // A file system without the exchange: move the earlier run aside, then the new one in. The
    // target is briefly absent, never a mixture.
    const std::string aside = staging_ + ".old";
    if (::rename(target_.c_str(), aside.c_str()) != 0)
      throw std::runtime_error("cannot replace '" + target_ + "': " + std::strerror(errno));
    if (::rename(staging_.c_str(), target_.c_str()) != 0) {
      const int err = errno;
      ::rename(aside.c_str(), target_.c_str());
      throw std::runtime_error("cannot move the outputs into '" + target_ + "': " + std::strerror(err));
    }
    committed_ = true;
    fs::remove_all(aside, ec);
    return;
  }
  committed_ = true;
  fs::remove_all(staging_, ec);
}

}  // namespace scoleid::io
