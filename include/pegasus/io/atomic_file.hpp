#pragma once
// Files that are either absent, the old version or the complete new version, even if the process is killed
// (SIGKILL, power loss) in the middle of writing: the text goes to a hidden temporary file next to the
// target, is flushed to disk, and is renamed over the target (rename is atomic on POSIX file systems).
#include <filesystem>
#include <string>
#include <string_view>

namespace pegasus {

// Creates missing parent folders. Throws std::runtime_error naming the file on failure.
void write_file_atomic(const std::filesystem::path& file, std::string_view content);

// The whole file; std::runtime_error naming the file if it cannot be read.
std::string read_file(const std::filesystem::path& file);

// SHA-256 of a file's bytes as 64 hex digits (OpenSSL); InputError naming the file when it cannot be read.
std::string file_sha256(const std::filesystem::path& file);
// The same of bytes in memory.
std::string sha256_hex(std::string_view bytes);

// The temporary name write_file_atomic uses for `file` (".NAME.tmp" in the same folder).
std::filesystem::path atomic_temp_path(const std::filesystem::path& file);

}  // namespace pegasus
