#ifndef PUZZLECAL_APPS_SUBCOMMAND_H_
#define PUZZLECAL_APPS_SUBCOMMAND_H_

#include <string>
#include <vector>

namespace puzzlecal {

// One `puzzlecal SUBCOMMAND` entry. Each apps/cmd_*.cc registers one with
// PUZZLECAL_REGISTER_SUBCOMMAND; main.cc dispatches on argv[1].
struct Subcommand {
  const char* name;     // e.g. "render"
  const char* summary;  // one line for `puzzlecal --help`
  const char* usage;    // synopsis and description for `puzzlecal NAME --help`
  // Names of the gflags this subcommand reads (shown by its --help).
  std::vector<std::string> flags;
  // Runs with flags already parsed; returns the process exit code.
  int (*run)();
  // How many plain arguments (file names, anywhere among the flags) it
  // takes; 0: none, a stray word is a usage error.
  int max_arguments = 0;
};

// Process exit codes (documented in README.md).
enum ExitCode {
  kExitOk = 0,
  kExitDrifted = 1,      // check: the calibration has drifted
  kExitUsage = 2,        // bad command line, unknown subcommand or model
  kExitBadInput = 3,     // unreadable or invalid input file or folder
  kExitNoResult = 4,     // inputs fine but no trustworthy result (too few
                         // usable views, degenerate geometry, no convergence)
  kExitOutputError = 5,  // the result could not be written
};

bool RegisterSubcommand(const Subcommand& subcommand);
const std::vector<Subcommand>& Subcommands();

// The plain arguments of the command line (see max_arguments), in order;
// set by main.cc before the subcommand runs.
const std::vector<std::string>& SubcommandArguments();
void SetSubcommandArguments(const std::vector<std::string>& arguments);

}  // namespace puzzlecal

#define PUZZLECAL_REGISTER_SUBCOMMAND(var, ...)  \
  static const bool puzzlecal_registered_##var = \
      ::puzzlecal::RegisterSubcommand(::puzzlecal::Subcommand{__VA_ARGS__})

#endif  // PUZZLECAL_APPS_SUBCOMMAND_H_
