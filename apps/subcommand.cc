#include "apps/subcommand.h"

namespace puzzlecal {
namespace {

std::vector<Subcommand>& Registry() {
  static std::vector<Subcommand> registry;
  return registry;
}

}  // namespace

bool RegisterSubcommand(const Subcommand& subcommand) {
  Registry().push_back(subcommand);
  return true;
}

const std::vector<Subcommand>& Subcommands() { return Registry(); }

}  // namespace puzzlecal
