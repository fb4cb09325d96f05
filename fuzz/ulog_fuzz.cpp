// libFuzzer harness for the ULog reader (logs/ulog.hpp). The error contract: on any bytes the reader returns
// or throws InputError, never anything else, and the message names the file and the byte offset
// ("NAME: byte N: ..."), with N inside the input. Both truncation policies are exercised, and every topic
// read is checked for consistency (records whole, one timestamp per record).
// Built by `make fuzz` with the others (fuzz/CMakeLists.txt), and replayed over its seed corpus by `make
// test`.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <span>
#include <string>

#include "fuzz_contract.hpp"
#include "pegasus/core/error.hpp"
#include "pegasus/io/atomic_file.hpp"
#include "pegasus/logs/ulog.hpp"

namespace {

void check_message(const std::string& message, std::size_t size) {
  const std::string prefix = "fuzz.ulg: byte ";
  if (message.rfind(prefix, 0) != 0) {
    std::fprintf(stderr, "InputError without the file and byte offset: %s\n", message.c_str());
    std::abort();
  }
  const std::size_t offset = std::strtoull(message.c_str() + prefix.size(), nullptr, 10);
  if (offset > size) {
    std::fprintf(stderr, "byte offset %zu beyond the input's %zu bytes: %s\n", offset, size, message.c_str());
    std::abort();
  }
}

void parse(std::span<const std::uint8_t> bytes, pegasus::logs::UlogReadOptions::TruncatedTail tail) {
  try {
    const pegasus::logs::UlogFile f =
        pegasus::logs::parse_ulog(bytes, "fuzz.ulg", {.truncated_tail = tail, .topics = {}});
    for (const auto& t : f.topics) {
      if (t.data.size() != t.rows() * t.record_size) std::abort();
      for (const auto& leaf : t.leaves)
        if (leaf.offset + leaf.count * pegasus::logs::ulog_type_size(leaf.type) > t.record_size) std::abort();
      for (std::size_t r = 0; r < t.rows(); ++r)
        for (const auto& leaf : t.leaves)
          if (leaf.count == 1) (void)t.value(leaf, r);
    }
    if (f.truncated_at && *f.truncated_at >= bytes.size()) std::abort();
  } catch (const pegasus::InputError& e) {
    check_message(e.what(), bytes.size());
  }
  // Any other exception escapes and libFuzzer reports it as a crash.
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  pegasus::fuzz::refuses_input_past_its_limit(
      [](const std::string& file) { (void)pegasus::logs::read_ulog(file); }, pegasus::kMaxDataFileBytes);
  const std::span<const std::uint8_t> bytes(data, size);
  parse(bytes, pegasus::logs::UlogReadOptions::TruncatedTail::kDiscard);
  parse(bytes, pegasus::logs::UlogReadOptions::TruncatedTail::kError);
  return 0;
}
