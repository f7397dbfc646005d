#include "scoleid/io/process.h"

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <stdexcept>

#include "scoleid/io/interrupt.h"

namespace scoleid::io {

ProcessResult run_program(const std::vector<std::string>& argv, const std::string& cwd) {
  if (argv.empty()) throw std::invalid_argument("run_program: empty argument vector");
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  // A pipe closed on exec tells the parent whether execvp succeeded.
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
  ProcessResult r;
  int child_errno = 0;
  ssize_t got;
  do {
    got = ::read(status_pipe[0], &child_errno, sizeof child_errno);
  } while (got < 0 && errno == EINTR && interrupt_signal() == 0);
  ::close(status_pipe[0]);
  r.started = got == 0;  // closed on a successful exec, nothing written
  int status = 0;
  for (;;) {
    const pid_t w = ::waitpid(pid, &status, 0);
    if (w == pid) break;
    if (w < 0 && errno == EINTR) {
      if (interrupt_signal() != 0) {
        ::kill(pid, SIGTERM);
        while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
        }
        check_interrupt();
      }
      continue;
    }
    throw std::runtime_error("run_program: waitpid failed");
  }
  check_interrupt();
  if (WIFEXITED(status)) r.exit_code = WEXITSTATUS(status);
  if (WIFSIGNALED(status)) r.signal = WTERMSIG(status);
  return r;
}

}  // namespace scoleid::io
