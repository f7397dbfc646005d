#pragma once
// The shell every program's main shares: its command line parsed, and what escapes a run turned
// into the exit code of the programs' footers, with one line on stderr:
//   0  success (or what the run returns)
//   1  the run failed (an integration failure, a solver's exception)     "PROG: run failed: …"
//   2  bad usage or bad input (io::InputError, a command-line error)     "PROG: …"
//   130/143  interrupted by SIGINT/SIGTERM (io::Interrupted)             "PROG: interrupted …"
// The staged outputs of a run that ends by an exception are discarded by its RunDirectory.
#include <functional>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

namespace scoleid::io {

// Runs `run` and maps what escapes it as above.
int guarded_main(const char* program, const std::function<int()>& run);

// Parses the command line: nullopt when the run goes on, else the exit code to return at once
// (0 after --help, 2 after a usage error, reported in one line).
std::optional<int> parse_command_line(CLI::App& app, int argc, char** argv, const char* program);

// --print-scenario NAME (the built-in as YAML) and --list-scenarios on stdout: true if either was
// asked for (the program then ends), false if neither.
bool print_builtin_scenarios(const std::string& print_name, bool list);

}  // namespace scoleid::io
