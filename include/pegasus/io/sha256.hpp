#pragma once
// SHA-256 digests (OpenSSL's libcrypto), for the provenance of inputs: a run directory's record of its input
// files, an imported log's source, a MuJoCo task's content. In their own library (pegasus::digest), so that
// pegasus::core links no OpenSSL.
#include <filesystem>
#include <string>
#include <string_view>

namespace pegasus {

// SHA-256 of a file's bytes as 64 hex digits; InputError naming the file when it cannot be read.
std::string file_sha256(const std::filesystem::path& file);
// The same of bytes in memory.
std::string sha256_hex(std::string_view bytes);

}  // namespace pegasus
