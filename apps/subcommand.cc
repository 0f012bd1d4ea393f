#include "apps/subcommand.h"

namespace puzzlecal {
namespace {

std::vector<Subcommand>& Registry() {
  static std::vector<Subcommand> registry;
  return registry;
}

std::vector<std::string>& Arguments() {
  static std::vector<std::string> arguments;
  return arguments;
}

}  // namespace

bool RegisterSubcommand(const Subcommand& subcommand) {
  Registry().push_back(subcommand);
  return true;
}

const std::vector<Subcommand>& Subcommands() { return Registry(); }

const std::vector<std::string>& SubcommandArguments() { return Arguments(); }

void SetSubcommandArguments(const std::vector<std::string>& arguments) {
  Arguments() = arguments;
}

}  // namespace puzzlecal
