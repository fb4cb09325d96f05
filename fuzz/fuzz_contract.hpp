#pragma once
// The error contract every reader keeps, checked by each libFuzzer harness on every input: a reader either
// accepts the bytes or throws pegasus::InputError whose message is one line and names the input. Anything
// else (another exception, a crash, a sanitizer report, a hang) is a finding; std::abort makes libFuzzer
// keep the input that broke the contract.
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

#include "pegasus/core/error.hpp"

namespace pegasus::fuzz {

[[noreturn]] inline void violation(std::string_view what, std::string_view message) {
  std::fprintf(stderr, "error contract broken: %.*s: [%.*s]\n", static_cast<int>(what.size()), what.data(),
               static_cast<int>(message.size()), message.data());
  std::abort();
}

// Runs `read`; an InputError must be one line that contains `input_name`; any other exception is a finding.
// Returns true when `read` accepted the input.
template <class Read>
bool keeps_error_contract(std::string_view input_name, Read&& read) {
  try {
    read();
    return true;
  } catch (const InputError& e) {
    const std::string_view message = e.what();
    if (message.empty()) violation("empty message", message);
    if (message.find('\n') != std::string_view::npos) violation("a message of more than one line", message);
    if (message.find(input_name) == std::string_view::npos)
      violation("a message that names no input", message);
    return false;
  } catch (const std::exception& e) {
    violation("an exception other than InputError", e.what());
  }
}

// The size-limit property (issue 51), checked once per process before the first input: the harness's reader,
// given its input as a file, refuses input past its limit at once. /dev/zero (a device without end) and a
// file one byte past `limit` (sparse: no byte of it is written or read) must each give one InputError line
// naming the file, within a second; a reader that read them would grow memory until libFuzzer's limit, or
// run past this one.
template <class ReadFile>
void refuses_input_past_its_limit(ReadFile&& read_file, std::uint64_t limit) {
  static const bool checked = [&] {
    char name[] = "/tmp/pegasus-fuzz-limit-XXXXXX";
    const int fd = ::mkstemp(name);
    if (fd < 0 || ::ftruncate(fd, static_cast<off_t>(limit + 1)) != 0)
      violation("cannot make the file", name);
    ::close(fd);
    for (const std::string& file : {std::string("/dev/zero"), std::string(name)}) {
      const auto start = std::chrono::steady_clock::now();
      if (keeps_error_contract(file, [&] { read_file(file); }))
        violation("input past the reader's limit was accepted", file);
      if (std::chrono::steady_clock::now() - start > std::chrono::seconds(1))
        violation("input past the reader's limit took over a second to refuse", file);
    }
    ::unlink(name);
    return true;
  }();
  (void)checked;
}

inline std::string_view as_text(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

}  // namespace pegasus::fuzz
