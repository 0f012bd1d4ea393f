// `puzzlecal options`: prints an options file holding every option with its
// default (or, with --options, with the values of that file), for a user to
// edit and pass to calibrate, detect or calibrate-rig with --options.

#include <iostream>
#include <string>

#include "apps/common_flags.h"
#include "apps/options_io.h"
#include "apps/subcommand.h"

namespace puzzlecal {
namespace {

constexpr char kUsage[] =
    "puzzlecal options [--options FILE] > my_options.yaml\n\n"
    "Prints an options file: every detection, grid, decoding, calibration,\n"
    "evidence, verdict, model-selection and rig option with its default, as\n"
    "the YAML that --options FILE reads (calibrate, detect, calibrate-rig).\n"
    "Keep the fields you change; a field left out keeps its default. With\n"
    "--options FILE it checks FILE and prints the options it gives.\n\n"
    "Exit codes: 0 done, 3 FILE is unreadable or invalid.";

int RunOptionsCommand() {
  RunOptions options;
  std::string error;
  if (!FLAGS_options.empty() &&
      !LoadOptionsFile(FLAGS_options, &options, &error)) {
    std::cerr << "puzzlecal options: " << error << "\n";
    return kExitBadInput;
  }
  std::cout << OptionsYaml(options);
  return kExitOk;
}

PUZZLECAL_REGISTER_SUBCOMMAND(options, "options",
                              "print every option with its default, as an "
                              "options file for --options",
                              kUsage, {"options"}, &RunOptionsCommand);

}  // namespace
}  // namespace puzzlecal
