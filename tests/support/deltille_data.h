#ifndef PUZZLECAL_TESTS_SUPPORT_DELTILLE_DATA_H_
#define PUZZLECAL_TESTS_SUPPORT_DELTILLE_DATA_H_

// Where the regression tests and benches find the deltille fisheye photos
// (README, "Regression data"): $PUZZLECAL_DATA/deltille/fisheye, else
// ../shared/deltille/fisheye relative to the working directory.

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

namespace puzzlecal {
namespace testing_data {

// The photo folder, or "" when neither place is a folder.
inline std::string DeltilleFolder() {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (const char* data = std::getenv("PUZZLECAL_DATA")) {
    const fs::path path = fs::path(data) / "deltille" / "fisheye";
    if (fs::is_directory(path, ec)) return path.string();
  }
  const fs::path shared = fs::path("..") / "shared" / "deltille" / "fisheye";
  if (fs::is_directory(shared, ec)) return shared.string();
  return "";
}

// The dataset's photos (NNNN.png) in `folder`, sorted by name (empty when
// there are none).
inline std::vector<std::string> DeltillePhotoFiles(const std::string& folder) {
  std::vector<std::string> files;
  std::error_code ec;
  if (folder.empty() || !std::filesystem::is_directory(folder, ec)) {
    return files;
  }
  for (const auto& entry : std::filesystem::directory_iterator(folder, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.size() == 8 && name.compare(4, 4, ".png") == 0 &&
        std::all_of(name.begin(), name.begin() + 4,
                    [](char c) { return c >= '0' && c <= '9'; })) {
      files.push_back(entry.path().string());
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

// How to get the photos, for skip messages.
inline const char* DeltilleHowToGet() {
  return "download github.com/deltille/dataset and set PUZZLECAL_DATA to a "
         "folder holding deltille/fisheye/*.png";
}

}  // namespace testing_data
}  // namespace puzzlecal

#endif  // PUZZLECAL_TESTS_SUPPORT_DELTILLE_DATA_H_
