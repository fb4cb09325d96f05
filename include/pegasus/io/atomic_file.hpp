#pragma once
// Files that are either absent, the old version or the complete new version, even if the process is killed
// (SIGKILL, power loss) in the middle of writing: the text goes to a hidden temporary file next to the
// target, is flushed to disk, and is renamed over the target (rename is atomic on POSIX file systems).
#include <cstdint>
#include <exception>
#include <filesystem>
#include <string>
#include <string_view>

namespace pegasus {

// Creates missing parent folders. Throws std::runtime_error naming the file on failure.
void write_file_atomic(const std::filesystem::path& file, std::string_view content);

// The largest input file a reader takes: past it, it refuses at once (a regular file, by its size) or as
// soon as that many bytes came (a pipe), so endless input (/dev/zero, `yes |`) ends in one line, not in
// memory growing until the machine stops it. Settings (TOML: configs, vehicle, task and manoeuvre files) are
// small; data (flight logs, ULogs, models, policies, summaries) may be long flights.
inline constexpr std::uint64_t kMaxSettingsFileBytes = std::uint64_t{16} << 20;  // 16 MiB
inline constexpr std::uint64_t kMaxDataFileBytes = std::uint64_t{2} << 30;       // 2 GiB

// The whole file: a regular file or a pipe of at most max_bytes; std::runtime_error "cannot read FILE:
// REASON" otherwise (a directory, a device such as /dev/zero, a socket, a larger file, a read error).
std::string read_file(const std::filesystem::path& file, std::uint64_t max_bytes = kMaxDataFileBytes);
// The same limit said as a reason ("larger than the 16 MiB limit of an input file").
std::string size_limit_reason(std::uint64_t max_bytes);
// The reason of a read_file failure without its "cannot read FILE: " (what a reader that names the file
// itself quotes).
std::string read_failure_reason(const std::exception& e);

// The temporary name write_file_atomic uses for `file` (".NAME.tmp" in the same folder).
std::filesystem::path atomic_temp_path(const std::filesystem::path& file);

}  // namespace pegasus
