#pragma once
// The second kind of error that crosses the library boundary (the first, InputError, is in error.hpp).
#include <stdexcept>
#include <string>

namespace pegasus {

// The machine refused what a correct run needs: a full disk, a missing permission, no thread or memory to be
// had. Not the input's fault, and not a bug; the message is one line naming the path or resource and the
// system's reason. The CLI turns it into exit code 3 (cli::kExitEnvironment), the same for every command.
class EnvironmentError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace pegasus
