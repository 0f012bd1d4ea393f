#ifndef PUZZLECAL_FUZZ_YAML_FILE_H_
#define PUZZLECAL_FUZZ_YAML_FILE_H_

// The YAML readers take paths: each fuzz case writes its bytes to a file of
// its own in the temporary folder (/dev/shm-backed where TMPDIR says so).

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

namespace puzzlecal {
namespace fuzz {

// A file holding the bytes, removed when the object goes.
class TemporaryFile {
 public:
  TemporaryFile(const uint8_t* data, size_t size, const std::string& name) {
    std::error_code ec;
    std::filesystem::path folder = std::filesystem::temp_directory_path(ec);
    if (ec) folder = ".";
    path_ = (folder / ("puzzlecal_fuzz_" + std::to_string(getpid()) + "_" +
                       name))
                .string();
    std::ofstream out(path_, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data),
              static_cast<std::streamsize>(size));
  }
  ~TemporaryFile() {
    std::error_code ec;
    std::filesystem::remove(path_, ec);
  }
  TemporaryFile(const TemporaryFile&) = delete;
  TemporaryFile& operator=(const TemporaryFile&) = delete;

  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

}  // namespace fuzz
}  // namespace puzzlecal

#endif  // PUZZLECAL_FUZZ_YAML_FILE_H_
