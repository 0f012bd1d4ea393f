#ifndef PUZZLECAL_TESTS_SUPPORT_FILES_H_
#define PUZZLECAL_TESTS_SUPPORT_FILES_H_

// Whole files read and written in one call, for tests that check what a
// program or a writer produced.

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace puzzlecal {
namespace testing_files {

// The whole file as bytes; "" when it cannot be read.
inline std::string ReadFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)),
                     std::istreambuf_iterator<char>());
}

// Replaces the file's contents with `bytes`.
inline void WriteFile(const std::filesystem::path& path,
                      const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << bytes;
}

}  // namespace testing_files
}  // namespace puzzlecal

#endif  // PUZZLECAL_TESTS_SUPPORT_FILES_H_
