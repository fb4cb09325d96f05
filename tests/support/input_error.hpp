#pragma once
// The message of the InputError a piece of code throws, for tests that check what users are told.
#include <string>
#include <utility>

#include "pegasus/core/error.hpp"

namespace pegasus::test_support {

// e.what() of the InputError that `f` throws, or "(no error)" when it throws none.
template <class F>
std::string input_error_message(F&& f) {
  try {
    std::forward<F>(f)();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace pegasus::test_support
