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

}  // namespace pegasus
