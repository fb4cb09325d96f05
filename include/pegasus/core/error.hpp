#pragma once
// Errors that cross the library boundary.
#include <stdexcept>
#include <string>

namespace pegasus {

// `message` as one printable line: line breaks become spaces, other control bytes and bytes that are not
// UTF-8 are written \xNN (core/untrusted_text.hpp), so that quoting a user's bytes can never break the
// one-line error contract.
std::string one_line_message(const std::string& message);

// Bad user input: a config value, option, file or parameter out of range. The message is one line that
// names the input (option, file:line, field) and what was expected. The CLI turns it into exit code 2.
class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message) : std::runtime_error(one_line_message(message)) {}
  explicit InputError(const char* message) : InputError(std::string(message)) {}
};

// The machine refused what a correct run needs: a full disk, a missing permission, no thread or memory to be
// had. Not the input's fault, and not a bug; the message names the path or resource and the system's
// reason. The CLI turns it into exit code 3 (cli::kExitEnvironment).
class EnvironmentError : public std::runtime_error {
 public:
  explicit EnvironmentError(const std::string& message) : std::runtime_error(one_line_message(message)) {}
};

}  // namespace pegasus
