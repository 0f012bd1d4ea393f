#ifndef PUZZLECAL_PIPELINE_FOLDER_WATCH_H_
#define PUZZLECAL_PIPELINE_FOLDER_WATCH_H_

// The photos arriving in a folder (a phone or a capture script writing into
// it), for `calibrate --watch`: each Poll() lists the folder and returns the
// image files it has not returned before, once their size has stayed the
// same over two polls (a file still being written is held back until it
// stops growing), sorted by name.

#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <vector>

namespace puzzlecal {

class FolderWatch {
 public:
  explicit FolderWatch(std::string dir) : dir_(std::move(dir)) {}

  // The new complete image files since the last call (full paths). False
  // with a message naming the folder when it cannot be read.
  bool Poll(std::vector<std::string>* new_files, std::string* error);

 private:
  std::string dir_;
  std::set<std::string> returned_;
  std::map<std::string, std::uintmax_t> last_size_;  // not yet returned
};

}  // namespace puzzlecal

#endif  // PUZZLECAL_PIPELINE_FOLDER_WATCH_H_
