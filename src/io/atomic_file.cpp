#include "pegasus/io/atomic_file.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "pegasus/core/environment_error.hpp"
#include "pegasus/core/error.hpp"

namespace pegasus {

namespace {

[[noreturn]] void fail(const std::string& what, const std::filesystem::path& file, int err) {
  throw EnvironmentError("cannot " + what + " " + file.string() + ": " + std::strerror(err));
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
  // A failed write (a full disk) leaves no temporary behind: in a committed run directory nothing would
  // ever remove it, and in a fresh DIR.partial it would pass for an interrupted run.
  auto fail_and_remove = [&](const std::string& what, int err) {
    ::unlink(temp.c_str());
    fail(what, temp, err);
  };
  const char* data = content.data();
  std::size_t left = content.size();
  while (left > 0) {
    const ssize_t n = ::write(fd, data, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      const int err = errno;
      ::close(fd);
      fail_and_remove("write", err);
    }
    data += n;
    left -= static_cast<std::size_t>(n);
  }
  // fsync before rename: otherwise a crash of the machine (not just the process) could leave the new name
  // pointing at an empty file.
  if (::fsync(fd) != 0) {
    const int err = errno;
    ::close(fd);
    fail_and_remove("flush", err);
  }
  if (::close(fd) != 0) fail_and_remove("flush", errno);
  if (std::rename(temp.c_str(), file.c_str()) != 0) {
    const int err = errno;
    ::unlink(temp.c_str());
    fail("rename into place", file, err);
  }
}

std::string size_limit_reason(std::uint64_t max_bytes) {
  return max_bytes % (std::uint64_t{1} << 30) == 0
             ? fmt::format("larger than the {} GiB limit of an input file", max_bytes >> 30)
             : fmt::format("larger than the {} MiB limit of an input file", max_bytes >> 20);
}

std::string read_failure_reason(const std::exception& e) {
  std::string reason = e.what();
  if (const auto colon = reason.rfind(": "); colon != std::string::npos) reason.erase(0, colon + 2);
  return reason;
}

std::string read_file(const std::filesystem::path& file, std::uint64_t max_bytes) {
  // Callers decide whose fault a read failure is (a user's input file, or the run's own), so this one stays
  // a plain runtime_error whose reason follows the last ": ".
  auto fail_read = [&](const std::string& reason) -> void {
    throw std::runtime_error("cannot read " + file.string() + ": " + reason);
  };
  // What is not a file's bytes is refused before it is opened: a device reads forever or blocks.
  auto check_kind = [&](const struct stat& st) {
    if (S_ISDIR(st.st_mode)) fail_read(std::strerror(EISDIR));
    if (S_ISCHR(st.st_mode) || S_ISBLK(st.st_mode)) fail_read("expected a regular file, got a device");
    if (S_ISSOCK(st.st_mode)) fail_read("expected a regular file, got a socket");
    if (S_ISREG(st.st_mode) && static_cast<std::uint64_t>(st.st_size) > max_bytes)
      fail_read(size_limit_reason(max_bytes));
  };
  struct stat st {};
  if (::stat(file.c_str(), &st) != 0) fail_read(std::strerror(errno));
  check_kind(st);
  const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) fail_read(std::strerror(errno));
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  if (::fstat(fd, &st) != 0) fail_read(std::strerror(errno));
  check_kind(st);  // what was opened, which a rename may have changed since the stat
  std::string text;
  // A regular file's stated size is read straight into place (a 4 MB ULog read 6% slower through the
  // buffer below: bench/ulog_bench.cpp); whatever else comes (a file grown since, a pipe) through the buffer.
  if (S_ISREG(st.st_mode)) {
    text.resize(static_cast<std::size_t>(st.st_size));
    std::size_t filled = 0;
    while (filled < text.size()) {
      const ssize_t n = ::read(fd, text.data() + filled, text.size() - filled);
      if (n < 0) {
        if (errno == EINTR) continue;
        fail_read(std::strerror(errno));
      }
      if (n == 0) break;
      filled += static_cast<std::size_t>(n);
    }
    text.resize(filled);  // a file shortened since the stat
  }
  std::vector<char> buffer(1 << 16);
  for (;;) {
    const ssize_t n = ::read(fd, buffer.data(), buffer.size());
    if (n < 0) {
      if (errno == EINTR) continue;
      fail_read(std::strerror(errno));
    }
    if (n == 0) break;
    if (text.size() + static_cast<std::uint64_t>(n) > max_bytes) fail_read(size_limit_reason(max_bytes));
    text.append(buffer.data(), static_cast<std::size_t>(n));
  }
  return text;
}

}  // namespace pegasus
