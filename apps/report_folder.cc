#include "apps/report_folder.h"

#include <unistd.h>

namespace puzzlecal {
namespace {

namespace fs = std::filesystem;

// Files a report folder holds (the reports' names).
bool IsReportFile(const fs::path& file) {
  const std::string name = file.filename().string();
  return name == "summary.md" || name == "index.html" ||
         file.extension() == ".png";
}

// Hidden names next to the report folder.
fs::path SiblingPath(const fs::path& dir, const std::string& suffix) {
  const fs::path parent =
      dir.parent_path().empty() ? fs::path(".") : dir.parent_path();
  return parent / ("." + dir.filename().string() + suffix);
}

}  // namespace

bool CheckReportFolder(const fs::path& dir, std::string* error) {
  std::error_code ec;
  if (fs::exists(dir, ec)) {
    if (!fs::is_directory(dir, ec)) {
      *error = "--report " + dir.string() + " is a file, not a folder";
      return false;
    }
    for (const auto& entry : fs::directory_iterator(dir, ec)) {
      if (!entry.is_regular_file() || !IsReportFile(entry.path())) {
        *error = "--report " + dir.string() + " holds " +
                 entry.path().filename().string() +
                 ", which is not part of a report; choose a new or empty "
                 "folder (a report folder is replaced as a whole)";
        return false;
      }
    }
  }
  const fs::path parent =
      dir.parent_path().empty() ? fs::path(".") : dir.parent_path();
  fs::create_directories(parent, ec);
  if (!fs::is_directory(parent, ec) || ::access(parent.c_str(), W_OK) != 0) {
    *error = "cannot write the report folder " + dir.string() + ": " +
             parent.string() + " is not a writable folder";
    return false;
  }
  return true;
}

bool WriteFolderInPlace(
    const fs::path& dir,
    const std::function<bool(const std::string&, std::string*)>& write,
    std::string* error) {
  std::error_code ec;
  const fs::path partial = SiblingPath(dir, ".partial");
  const fs::path old = SiblingPath(dir, ".old");
  fs::remove_all(partial, ec);
  fs::remove_all(old, ec);
  if (!write(partial.string(), error)) {
    fs::remove_all(partial, ec);
    return false;
  }
  if (fs::exists(dir, ec)) fs::rename(dir, old, ec);
  if (!ec) fs::rename(partial, dir, ec);
  if (ec) {
    *error = "cannot put the report in place at " + dir.string() + ": " +
             ec.message();
    fs::remove_all(partial, ec);
    return false;
  }
  fs::remove_all(old, ec);
  return true;
}

}  // namespace puzzlecal
