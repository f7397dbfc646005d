#include "scoleid/io/program.h"

#include <csignal>
#include <cstdio>
#include <exception>

#include "scoleid/io/builtin.h"
#include "scoleid/io/error.h"
#include "scoleid/io/interrupt.h"
#include "scoleid/io/validation.h"

namespace scoleid::io {

int guarded_main(const char* program, const std::function<int()>& run) {
  try {
    return run();
  } catch (const InputError& e) {
    std::fprintf(stderr, "%s: %s\n", program, one_line(e.what()).c_str());
    return 2;
  } catch (const Interrupted& e) {
    // A fresh line: a progress line may be open on stderr.
    if (e.signal() == SIGALRM) {  // scole-identify's --max-wall-time, before there was an iterate to keep
      std::fprintf(stderr, "\n%s: stopped at the wall-time limit (--max-wall-time) before the first iterate; no output written\n", program);
      return 1;
    }
    std::fprintf(stderr, "\n%s: %s\n", program, e.what());
    return e.exit_code();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: run failed: %s\n", program, one_line(e.what()).c_str());
    return 1;
  }
}

bool print_builtin_scenarios(const std::string& print_name, bool list) {
  if (!print_name.empty()) {
    std::string text;
    try {
      text = builtin_scenario_text(print_name);
    } catch (const InputError& e) {
      throw InputError(std::string("--print-scenario: ") + e.what());
    }
    std::fputs(text.c_str(), stdout);
    return true;
  }
  if (list) {
    std::fputs(builtin_scenario_listing().c_str(), stdout);
    return true;
  }
  return false;
}

std::optional<int> parse_command_line(CLI::App& app, int argc, char** argv, const char* program) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --help-all
    std::fprintf(stderr, "%s: %s (see --help)\n", program, one_line(e.what()).c_str());
    return 2;
  }
  return std::nullopt;
}

}  // namespace scoleid::io
