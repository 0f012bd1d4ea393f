#include "util/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <vector>

#include "util/failure.h"

namespace puzzlecal {
namespace {

std::string ErrnoText(int err) { return std::strerror(err); }

// The folder that holds `path` ("." for a bare file name).
std::string DirectoryOf(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  if (slash == 0) return "/";
  return path.substr(0, slash);
}

}  // namespace

bool WriteFileAtomically(const std::string& path, const std::string& contents,
                         std::string* error) {
  if (path.empty()) return Fail("cannot write a file with an empty path", error);
  if (path.back() == '/') {
    return Fail("cannot write '" + path + "': the path names a folder", error);
  }
  struct stat info;
  if (stat(path.c_str(), &info) == 0 && S_ISDIR(info.st_mode)) {
    return Fail("cannot write '" + path + "': it is a folder", error);
  }
  // mkstemp needs a writable template; the temporary file lives next to the
  // target so that rename() stays on one file system and is atomic.
  std::string temp_name = path + ".tmp.XXXXXX";
  std::vector<char> temp(temp_name.begin(), temp_name.end());
  temp.push_back('\0');
  const int fd = mkstemp(temp.data());
  if (fd < 0) {
    const int err = errno;
    return Fail("cannot write '" + path + "': cannot create a temporary file "
                "in '" + DirectoryOf(path) + "': " + ErrnoText(err), error);
  }
  temp_name = temp.data();
  auto abandon = [&](const std::string& what, int err) {
    close(fd);
    unlink(temp_name.c_str());
    return Fail("cannot write '" + path + "': " + what + ": " + ErrnoText(err),
                error);
  };
  size_t written = 0;
  while (written < contents.size()) {
    const ssize_t n =
        write(fd, contents.data() + written, contents.size() - written);
    if (n < 0) {
      if (errno == EINTR) continue;
      return abandon("write failed", errno);
    }
    written += static_cast<size_t>(n);
  }
  // mkstemp creates the file with mode 0600; result files are ordinary
  // documents, so give them the usual permissions (subject to the umask).
  const mode_t mask = umask(0);
  umask(mask);
  if (fchmod(fd, 0666 & ~mask) != 0) return abandon("chmod failed", errno);
  if (fsync(fd) != 0) return abandon("fsync failed", errno);
  if (close(fd) != 0) {
    const int err = errno;
    unlink(temp_name.c_str());
    return Fail("cannot write '" + path + "': close failed: " + ErrnoText(err),
                error);
  }
  if (rename(temp_name.c_str(), path.c_str()) != 0) {
    const int err = errno;
    unlink(temp_name.c_str());
    return Fail("cannot write '" + path + "': rename failed: " + ErrnoText(err),
                error);
  }
  // Make the rename itself durable.
  const int dir_fd = open(DirectoryOf(path).c_str(), O_RDONLY | O_DIRECTORY);
  if (dir_fd >= 0) {
    fsync(dir_fd);
    close(dir_fd);
  }
  return true;
}

}  // namespace puzzlecal
