#include "pipeline/folder_watch.h"

#include <algorithm>
#include <filesystem>

#include "formats/image_io.h"

namespace puzzlecal {

namespace fs = std::filesystem;

bool FolderWatch::Poll(std::vector<std::string>* new_files,
                       std::string* error) {
  new_files->clear();
  std::error_code ec;
  fs::directory_iterator it(dir_, ec);
  if (ec) {
    *error = dir_ + ": cannot read the folder: " + ec.message();
    return false;
  }
  std::map<std::string, std::uintmax_t> sizes;
  for (const fs::directory_entry& entry : it) {
    std::error_code entry_ec;
    if (!entry.is_regular_file(entry_ec) || !HasImageExtension(entry.path())) {
      continue;
    }
    const std::string path = entry.path().string();
    if (returned_.count(path)) continue;
    const std::uintmax_t size = entry.file_size(entry_ec);
    if (entry_ec) continue;
    sizes[path] = size;
  }
  for (const auto& [path, size] : sizes) {
    const auto last = last_size_.find(path);
    if (size > 0 && last != last_size_.end() && last->second == size) {
      new_files->push_back(path);
      returned_.insert(path);
    }
  }
  last_size_.clear();
  for (const auto& [path, size] : sizes) {
    if (!returned_.count(path)) last_size_[path] = size;
  }
  std::sort(new_files->begin(), new_files->end());
  return true;
}

}  // namespace puzzlecal
