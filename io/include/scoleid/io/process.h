#pragma once
// Running a helper program (gnuplot) without a shell: fork, chdir, execvp with an argument
// vector. Nothing a user typed — a directory name, a sensor name — is ever parsed as a command.
#include <cstddef>
#include <string>
#include <vector>

namespace scoleid::io {

struct ProcessResult {
  bool started = false;   // false: the program is not installed (execvp failed)
  int exit_code = -1;     // the child's exit status when it exited normally
  int signal = 0;         // the signal that ended it, if one did
  bool ok() const { return started && exit_code == 0 && signal == 0; }
};

// Runs argv[0] (searched in PATH) with the given arguments in directory `cwd`, stdin from
// /dev/null, stdout and stderr to /dev/null. Waits for it. If this process receives SIGINT or
// SIGTERM meanwhile (interrupt.h), the child is terminated and Interrupted is thrown.
ProcessResult run_program(const std::vector<std::string>& argv, const std::string& cwd);
// Runs several programs at once (as run_program each) and waits for all; their results in order.
// At most `max_running` run at a time (0: one per hardware thread): in that many at a time, in the
// order given, each group waited for before the next starts. An interrupt terminates every one
// still running and starts no more.
std::vector<ProcessResult> run_programs(const std::vector<std::vector<std::string>>& argvs, const std::string& cwd,
                                        std::size_t max_running = 0);

}  // namespace scoleid::io
