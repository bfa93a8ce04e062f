// Writing a whole file with every call checked: open, every write, fsync and
// close. A full disk (ENOSPC) or any other failure throws with the path and
// the system's reason, and leaves no file behind at `path`; what was there
// before is gone, so callers write to a partial name and rename.
#pragma once

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstddef>
#include <cstring>
#include <stdexcept>
#include <string>

namespace mpmvv::io {

inline void write_file(const std::string& path, const void* data, std::size_t size) {
  auto fail = [&](const char* what, int code, int fd) {
    if (fd >= 0) ::close(fd);
    ::unlink(path.c_str());
    throw std::runtime_error("cannot write " + path + " (" + what + "): " + std::strerror(code));
  };
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) fail("open", errno, -1);
  const char* p = static_cast<const char*>(data);
  for (std::size_t left = size; left > 0;) {
    const ssize_t n = ::write(fd, p, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      fail("write", errno, fd);
    }
    p += n;
    left -= std::size_t(n);
  }
  // A file system may report a full disk only when the data reach it.
  if (::fsync(fd) != 0 && errno != EINVAL) fail("fsync", errno, fd);
  if (::close(fd) != 0) fail("close", errno, -1);
}

inline void write_file(const std::string& path, const std::string& text) { write_file(path, text.data(), text.size()); }

}  // namespace mpmvv::io
