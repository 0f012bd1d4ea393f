#ifndef PUZZLECAL_APPS_REPORT_FOLDER_H_
#define PUZZLECAL_APPS_REPORT_FOLDER_H_

// Report folders of `calibrate` and `calibrate-rig`: checked before the
// work, built aside in a hidden sibling folder, then put in place of the
// old one as a whole (never mixed with other files).

#include <filesystem>
#include <functional>
#include <string>

namespace puzzlecal {

// Checked before the work: `dir` is new, or a folder holding only a report
// (summary.md and PNGs; it is replaced, old overlays included); its parent
// can be created and written. False with a message naming --report.
bool CheckReportFolder(const std::filesystem::path& dir, std::string* error);

// Runs `write(folder, error)` on a hidden folder next to `dir`, then puts
// that folder in place of `dir` (the old report goes). A failed write
// leaves `dir` as it was.
bool WriteFolderInPlace(
    const std::filesystem::path& dir,
    const std::function<bool(const std::string&, std::string*)>& write,
    std::string* error);

}  // namespace puzzlecal

#endif  // PUZZLECAL_APPS_REPORT_FOLDER_H_
