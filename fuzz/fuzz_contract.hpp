#pragma once
// The error contract every reader keeps, checked by each libFuzzer harness on every input: a reader either
// accepts the bytes or throws pegasus::InputError whose message is one line and names the input. Anything
// else (another exception, a crash, a sanitizer report, a hang) is a finding; std::abort makes libFuzzer
// keep the input that broke the contract.
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

inline std::string_view as_text(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

}  // namespace pegasus::fuzz
