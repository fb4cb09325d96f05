#include "pegasus/io/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace pegasus {

namespace {

[[noreturn]] void fail(const std::string& what, const std::filesystem::path& file, int err) {
  throw std::runtime_error("cannot " + what + " " + file.string() + ": " + std::strerror(err));
}

}  // namespace

std::filesystem::path atomic_temp_path(const std::filesystem::path& file) {
  return file.parent_path() / ("." + file.filename().string() + ".tmp");
}

void write_file_atomic(const std::filesystem::path& file, std::string_view content) {
  if (file.has_parent_path()) {
    std::error_code ec;
    std::filesystem::create_directories(file.parent_path(), ec);
    if (ec) fail("create the folder of", file, ec.value());
  }
  const std::filesystem::path temp = atomic_temp_path(file);
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) fail("write", temp, errno);
  const char* data = content.data();
  std::size_t left = content.size();
  while (left > 0) {
    const ssize_t n = ::write(fd, data, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      const int err = errno;
      ::close(fd);
      fail("write", temp, err);
    }
    data += n;
    left -= static_cast<std::size_t>(n);
  }
  // fsync before rename: otherwise a crash of the machine (not just the process) could leave the new name
  // pointing at an empty file.
  if (::fsync(fd) != 0 || ::close(fd) != 0) fail("flush", temp, errno);
  if (std::rename(temp.c_str(), file.c_str()) != 0) fail("rename into place", file, errno);
}

std::string read_file(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) fail("read", file, errno != 0 ? errno : ENOENT);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace pegasus
