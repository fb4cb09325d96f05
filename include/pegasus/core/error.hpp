#pragma once
// Errors that cross the library boundary.
#include <stdexcept>
#include <string>

namespace pegasus {

// Bad user input: a config value, option, file or parameter out of range. The message is one line that
// names the input (option, file:line, field) and what was expected. The CLI turns it into exit code 2.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The machine refused what a correct run needs: a full disk, a missing permission, no thread or memory to be
// had. Not the input's fault, and not a bug; the message names the path or resource and the system's
// reason. The CLI turns it into exit code 3 (cli::kExitEnvironment).
class EnvironmentError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace pegasus
