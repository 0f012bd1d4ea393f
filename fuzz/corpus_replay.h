#ifndef PUZZLECAL_FUZZ_CORPUS_REPLAY_H_
#define PUZZLECAL_FUZZ_CORPUS_REPLAY_H_

// Replaying a fuzz corpus in the normal test build: the regression tests feed
// every committed seed and kept crash input through the fuzz target's code.

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace puzzlecal {
namespace fuzz {

inline std::vector<uint8_t> ReadCorpusFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<uint8_t>((std::istreambuf_iterator<char>(in)),
                              std::istreambuf_iterator<char>());
}

// Calls `check(file name, bytes)` for every file of `corpus`, in name order;
// returns how many there were (-1 when `corpus` is not a folder).
template <typename Check>
int ReplayCorpus(const std::filesystem::path& corpus, Check&& check) {
  if (!std::filesystem::is_directory(corpus)) return -1;
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(corpus)) {
    files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  for (const auto& file : files) {
    check(file.filename().string(), ReadCorpusFile(file));
  }
  return static_cast<int>(files.size());
}

}  // namespace fuzz
}  // namespace puzzlecal

#endif  // PUZZLECAL_FUZZ_CORPUS_REPLAY_H_
