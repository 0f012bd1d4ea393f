// `puzzlecal version`: prints the program version.

#include <iostream>

#include "apps/subcommand.h"

namespace puzzlecal {
namespace {

int RunVersion() {
  std::cout << "puzzlecal 0.1.0\n";
  return kExitOk;
}

PUZZLECAL_REGISTER_SUBCOMMAND(version, "version", "print the version",
                              "puzzlecal version: prints the version.", {},
                              &RunVersion);

}  // namespace
}  // namespace puzzlecal
