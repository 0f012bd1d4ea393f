// puzzlecal: one program, several subcommands (apps/cmd_*.cc).

#include <gflags/gflags.h>
#include <glog/logging.h>

#include <algorithm>
#include <cctype>
#include <cstring>
#include <iostream>
#include <iterator>
#include <string>
#include <vector>

#include "apps/common_flags.h"
#include "apps/subcommand.h"

namespace puzzlecal {
namespace {

std::vector<Subcommand> SortedSubcommands() {
  std::vector<Subcommand> all = Subcommands();
  std::sort(all.begin(), all.end(),
            [](const Subcommand& a, const Subcommand& b) {
              return std::strcmp(a.name, b.name) < 0;
            });
  return all;
}

void PrintProgramHelp() {
  std::cout << "puzzlecal: camera calibration from photos of a PuzzleBoard or "
               "checkerboard.\n\nUsage: puzzlecal SUBCOMMAND [--flags]\n\n"
               "Subcommands:\n";
  // The summaries start in one column, after the longest name.
  size_t width = 0;
  for (const Subcommand& s : SortedSubcommands()) {
    width = std::max(width, std::strlen(s.name));
  }
  for (const Subcommand& s : SortedSubcommands()) {
    std::cout << "  " << s.name
              << std::string(width + 2 - std::strlen(s.name), ' ') << s.summary
              << "\n";
  }
  std::cout << "\n`puzzlecal help SUBCOMMAND` (or `puzzlecal SUBCOMMAND "
               "--help`) explains one subcommand;\n`puzzlecal --version` "
               "prints the version. Every subcommand takes --quiet and "
               "--verbose.\n";
}

// True when --NAME appears in the synopsis (the usage up to its first blank
// line) outside square brackets and parentheses (a remark such as "(MODEL:
// see --model below)" names a flag without requiring it): a flag the
// subcommand needs.
bool IsRequiredFlag(const Subcommand& s, const std::string& name) {
  const std::string usage = s.usage;
  const std::string synopsis = usage.substr(0, usage.find("\n\n"));
  std::string dashed = name;
  std::replace(dashed.begin(), dashed.end(), '_', '-');
  for (const std::string& spelling : {name, dashed}) {
    const std::string needle = "--" + spelling;
    for (size_t at = synopsis.find(needle); at != std::string::npos;
         at = synopsis.find(needle, at + 1)) {
      const size_t end = at + needle.size();
      if (end < synopsis.size() &&
          (std::isalnum(synopsis[end]) || synopsis[end] == '_' ||
           synopsis[end] == '-')) {
        continue;  // a longer flag name
      }
      int depth = 0;
      for (size_t k = 0; k < at; ++k) {
        const char c = synopsis[k];
        depth += (c == '[' || c == '(') ? 1 : (c == ']' || c == ')') ? -1 : 0;
      }
      if (depth == 0) return true;
    }
  }
  return false;
}

void PrintSubcommandHelp(const Subcommand& s) {
  std::cout << s.usage << "\n\nFlags:\n";
  std::vector<std::string> names = s.flags;
  for (const char* common : {"quiet", "verbose"}) {
    if (std::find(names.begin(), names.end(), common) == names.end()) {
      names.push_back(common);
    }
  }
  for (const std::string& name : names) {
    gflags::CommandLineFlagInfo info;
    if (!gflags::GetCommandLineFlagInfo(name.c_str(), &info)) continue;
    std::string dashed = info.name;
    std::replace(dashed.begin(), dashed.end(), '_', '-');
    std::cout << "  --" << dashed;
    if (IsRequiredFlag(s, name)) {
      std::cout << " (required)";
    } else if (info.default_value.empty()) {
      std::cout << " (optional)";
    } else if (info.type != "bool" || info.default_value != "false") {
      std::cout << " (default: " << info.default_value << ")";
    }
    std::cout << "\n      " << info.description << "\n";
  }
}

// Flags every subcommand accepts: how much it prints, and glog's own.
bool IsCommonFlag(const std::string& name) {
  return name == "quiet" || name == "verbose";
}

// Logging flags every subcommand accepts (glog's own).
bool IsLoggingFlag(const std::string& name) {
  static const char* const kLogging[] = {
      "v",           "vmodule",         "logtostderr",     "alsologtostderr",
      "minloglevel", "stderrthreshold", "colorlogtostderr"};
  return std::find(std::begin(kLogging), std::end(kLogging), name) !=
         std::end(kLogging);
}

// Parses `args` (after the subcommand; args[0] is the program) as
// --name=value, --name value, --bool_flag and --nobool_flag, and the plain
// arguments the subcommand takes (max_arguments) into `plain`. Unknown
// flags, flags the subcommand does not read, bad values and stray
// arguments are errors (gflags would exit with 1 on its own; the
// documented code is 2).
bool ParseSubcommandFlags(const Subcommand& subcommand,
                          const std::vector<char*>& args,
                          std::vector<std::string>* plain, std::string* error) {
  for (size_t i = 1; i < args.size(); ++i) {
    std::string arg = args[i];
    if (arg.size() < 2 || arg[0] != '-') {
      if (static_cast<int>(plain->size()) < subcommand.max_arguments) {
        plain->push_back(arg);
        continue;
      }
      *error = "unexpected argument '" + arg + "'";
      return false;
    }
    arg.erase(0, arg[1] == '-' ? 2 : 1);
    std::string flag = arg, value;
    const size_t equals = arg.find('=');
    const bool has_value = equals != std::string::npos;
    if (has_value) {
      flag = arg.substr(0, equals);
      value = arg.substr(equals + 1);
    }
    // --camera-name and --camera_name are the same flag.
    std::replace(flag.begin(), flag.end(), '-', '_');
    gflags::CommandLineFlagInfo info;
    bool found = gflags::GetCommandLineFlagInfo(flag.c_str(), &info);
    if (!found && !has_value && flag.rfind("no", 0) == 0 &&
        gflags::GetCommandLineFlagInfo(flag.substr(2).c_str(), &info) &&
        info.type == "bool") {
      flag = flag.substr(2);
      value = "false";
      found = true;
    } else if (found && !has_value) {
      if (info.type == "bool") {
        value = "true";
      } else if (i + 1 < args.size()) {
        value = args[++i];
      } else {
        *error = "flag --" + flag + " needs a value";
        return false;
      }
    }
    if (!found) {
      *error = "unknown flag --" + flag;
      return false;
    }
    const bool listed =
        std::find(subcommand.flags.begin(), subcommand.flags.end(), flag) !=
        subcommand.flags.end();
    if (!listed && !IsLoggingFlag(flag) && !IsCommonFlag(flag)) {
      *error =
          "flag --" + flag + " does not apply to `" + subcommand.name + "`";
      return false;
    }
    if (gflags::SetCommandLineOption(flag.c_str(), value.c_str()).empty()) {
      *error = "invalid value '" + value + "' for --" + flag + " (" +
               info.type + ")";
      return false;
    }
  }
  return true;
}

int Main(int argc, char** argv) {
  if (argc < 2 || std::strcmp(argv[1], "--help") == 0 ||
      std::strcmp(argv[1], "-h") == 0 ||
      (std::strcmp(argv[1], "help") == 0 && argc == 2)) {
    PrintProgramHelp();
    return argc < 2 ? kExitUsage : kExitOk;
  }
  const bool help_for = std::strcmp(argv[1], "help") == 0;  // help NAME
  std::string name = help_for ? argv[2] : argv[1];
  if (name == "--version" || name == "-V") name = "version";
  const auto& all = Subcommands();
  auto it = std::find_if(all.begin(), all.end(),
                         [&](const Subcommand& s) { return name == s.name; });
  if (it == all.end()) {
    std::cerr << "puzzlecal: unknown subcommand '" << name
              << "'. Run `puzzlecal --help` for the list.\n";
    return kExitUsage;
  }
  if (help_for) {
    PrintSubcommandHelp(*it);
    return kExitOk;
  }
  // Drop the subcommand from argv and parse the rest as flags.
  std::vector<char*> args;
  args.push_back(argv[0]);
  bool help = false;
  for (int i = 2; i < argc; ++i) {
    if (std::strcmp(argv[i], "--help") == 0 ||
        std::strcmp(argv[i], "-h") == 0 || std::strcmp(argv[i], "-help") == 0) {
      help = true;
    } else {
      args.push_back(argv[i]);
    }
  }
  if (help) {
    PrintSubcommandHelp(*it);
    return kExitOk;
  }
  std::string error;
  std::vector<std::string> plain;
  if (!ParseSubcommandFlags(*it, args, &plain, &error)) {
    std::cerr << "puzzlecal " << name << ": " << error << ". Run `puzzlecal "
              << name << " --help`.\n";
    return kExitUsage;
  }
  if (FLAGS_quiet && FLAGS_verbose) {
    std::cerr << "puzzlecal " << name
              << ": --quiet and --verbose exclude each other.\n";
    return kExitUsage;
  }
  // User-facing lines are plain text; library logging (Ceres, glog) only
  // shows errors unless --verbose.
  FLAGS_logtostderr = true;
  if (!FLAGS_verbose &&
      gflags::GetCommandLineFlagInfoOrDie("minloglevel").is_default) {
    FLAGS_minloglevel = google::GLOG_ERROR;
  }
  google::InitGoogleLogging(argv[0]);
  SetSubcommandArguments(plain);
  return it->run();
}

}  // namespace
}  // namespace puzzlecal

int main(int argc, char** argv) { return puzzlecal::Main(argc, argv); }
