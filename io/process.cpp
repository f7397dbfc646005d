#include "scoleid/io/process.h"

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <stdexcept>
#include <thread>

#include "scoleid/io/interrupt.h"

namespace scoleid::io {

namespace {

struct Child {
  pid_t pid = -1;
  bool started = false;
};

// Forks and execs argv in cwd, stdin/stdout/stderr on /dev/null; returns once the exec has
// succeeded or failed (a pipe closed on exec tells which).
Child start_child(const std::vector<std::string>& argv, const std::string& cwd) {
  if (argv.empty()) throw std::invalid_argument("run_program: empty argument vector");
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  int status_pipe[2];
  if (::pipe2(status_pipe, O_CLOEXEC) != 0) throw std::runtime_error("run_program: pipe failed");
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(status_pipe[0]);
    ::close(status_pipe[1]);
    throw std::runtime_error("run_program: fork failed");
  }
  if (pid == 0) {
    // Child: only async-signal-safe calls from here on.
    ::close(status_pipe[0]);
    signal(SIGINT, SIG_DFL);
    signal(SIGTERM, SIG_DFL);
    const int devnull = ::open("/dev/null", O_RDWR);
    if (devnull >= 0) {
      ::dup2(devnull, 0);
      ::dup2(devnull, 1);
      ::dup2(devnull, 2);
    }
    int err = 0;
    if (::chdir(cwd.c_str()) != 0) {
      err = errno;
    } else {
      ::execvp(args[0], args.data());
      err = errno;
    }
    const ssize_t w = ::write(status_pipe[1], &err, sizeof err);
    (void)w;
    ::_exit(127);
  }
  ::close(status_pipe[1]);
  int child_errno = 0;
  ssize_t got;
  do {
    got = ::read(status_pipe[0], &child_errno, sizeof child_errno);
  } while (got < 0 && errno == EINTR && interrupt_signal() == 0);
  ::close(status_pipe[0]);
  return {pid, got == 0};  // closed on a successful exec, nothing written
}

// Terminates and reaps every child not yet reaped (pid > 0).
void end_children(std::vector<Child>& children) {
  for (auto& c : children)
    if (c.pid > 0) ::kill(c.pid, SIGTERM);
  for (auto& c : children)
    if (c.pid > 0) {
      int status = 0;
      while (::waitpid(c.pid, &status, 0) < 0 && errno == EINTR) {
      }
      c.pid = -1;
    }
}

}  // namespace

std::vector<ProcessResult> run_programs(const std::vector<std::vector<std::string>>& argvs, const std::string& cwd,
                                        std::size_t max_running) {
  const std::size_t cap = max_running > 0 ? max_running : std::max(1u, std::thread::hardware_concurrency());
  std::vector<ProcessResult> results(argvs.size());
  for (std::size_t first = 0; first < argvs.size(); first += cap) {
    const std::size_t end = std::min(argvs.size(), first + cap);
    std::vector<Child> children;
    try {
      for (std::size_t i = first; i < end; ++i) children.push_back(start_child(argvs[i], cwd));
      for (std::size_t i = 0; i < children.size(); ++i) {
        Child& c = children[i];
        ProcessResult& res = results[first + i];
        res.started = c.started;
        int status = 0;
        for (;;) {
          const pid_t w = ::waitpid(c.pid, &status, 0);
          if (w == c.pid) break;
          if (w < 0 && errno == EINTR) {
            if (interrupt_signal() != 0) {
              end_children(children);
              check_interrupt();
            }
            continue;
          }
          throw std::runtime_error("run_program: waitpid failed");
        }
        c.pid = -1;
        if (WIFEXITED(status)) res.exit_code = WEXITSTATUS(status);
        if (WIFSIGNALED(status)) res.signal = WTERMSIG(status);
      }
    } catch (...) {
      end_children(children);
      throw;
    }
    check_interrupt();
  }
  return results;
}

ProcessResult run_program(const std::vector<std::string>& argv, const std::string& cwd) {
  return run_programs({argv}, cwd).front();
}

}  // namespace scoleid::io
