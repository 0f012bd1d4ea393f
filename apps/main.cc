// puzzlecal: one program, several subcommands (apps/cmd_*.cc).

#include <algorithm>
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

#include <gflags/gflags.h>
#include <glog/logging.h>

#include "apps/subcommand.h"

namespace puzzlecal {
namespace {

std::vector<Subcommand> SortedSubcommands() {
  std::vector<Subcommand> all = Subcommands();
  std::sort(all.begin(), all.end(), [](const Subcommand& a, const Subcommand& b) {
    return std::strcmp(a.name, b.name) < 0;
  });
  return all;
}

void PrintProgramHelp() {
  std::cout << "puzzlecal: camera calibration from photos of a PuzzleBoard or "
               "checkerboard.\n\nUsage: puzzlecal SUBCOMMAND [--flags]\n\n"
               "Subcommands:\n";
  for (const Subcommand& s : SortedSubcommands()) {
    std::cout << "  " << s.name << std::string(12 - std::strlen(s.name), ' ')
              << s.summary << "\n";
  }
  std::cout << "\n`puzzlecal SUBCOMMAND --help` explains one subcommand.\n";
}

void PrintSubcommandHelp(const Subcommand& s) {
  std::cout << s.usage << "\n\nFlags:\n";
  for (const std::string& name : s.flags) {
    gflags::CommandLineFlagInfo info;
    if (!gflags::GetCommandLineFlagInfo(name.c_str(), &info)) continue;
    std::cout << "  --" << info.name << " (" << info.description
              << ") default: \"" << info.default_value << "\"\n";
  }
}

int Main(int argc, char** argv) {
  if (argc < 2 || std::strcmp(argv[1], "--help") == 0 ||
      std::strcmp(argv[1], "-h") == 0 || std::strcmp(argv[1], "help") == 0) {
    PrintProgramHelp();
    return argc < 2 ? kExitUsage : kExitOk;
  }
  const std::string name = argv[1];
  const auto& all = Subcommands();
  auto it = std::find_if(all.begin(), all.end(),
                         [&](const Subcommand& s) { return name == s.name; });
  if (it == all.end()) {
    std::cerr << "puzzlecal: unknown subcommand '" << name
              << "'. Run `puzzlecal --help` for the list.\n";
    return kExitUsage;
  }
  // Drop the subcommand from argv and parse the rest as flags.
  std::vector<char*> args;
  args.push_back(argv[0]);
  bool help = false;
  for (int i = 2; i < argc; ++i) {
    if (std::strcmp(argv[i], "--help") == 0 || std::strcmp(argv[i], "-h") == 0 ||
        std::strcmp(argv[i], "-help") == 0) {
      help = true;
    } else {
      args.push_back(argv[i]);
    }
  }
  if (help) {
    PrintSubcommandHelp(*it);
    return kExitOk;
  }
  int new_argc = static_cast<int>(args.size());
  char** new_argv = args.data();
  gflags::SetUsageMessage(it->usage);
  gflags::ParseCommandLineNonHelpFlags(&new_argc, &new_argv, true);
  if (new_argc > 1) {
    std::cerr << "puzzlecal " << name << ": unexpected argument '"
              << new_argv[1] << "'. Run `puzzlecal " << name
              << " --help`.\n";
    return kExitUsage;
  }
  FLAGS_logtostderr = true;
  google::InitGoogleLogging(argv[0]);
  return it->run();
}

}  // namespace
}  // namespace puzzlecal

int main(int argc, char** argv) { return puzzlecal::Main(argc, argv); }
