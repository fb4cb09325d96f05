// libFuzzer harness: the `heli control` line protocol (heli/control_loop: run_control_loop). The contract
// of a line server: one answer line per input line, and for each malformed line exactly one stderr line that
// names it (issue 16: a NUL byte cut a message and merged two of them into one line); under a refused header
// (issue 51) no line is served from the input.
#include <cstdio>
#include <string>

#include "fuzz_contract.hpp"
#include "pegasus/heli/control_loop.hpp"

namespace {

// A controller that answers a fixed, valid command: the protocol is under test, not a policy.
class FixedController : public pegasus::heli::HeliController {
 public:
  using pegasus::heli::HeliController::act;
  pegasus::heli::Controls act(const pegasus::heli::LoggedState&, double,
                              pegasus::heli::ControllerMemory&) const override {
    return {0.1, -0.1, 0.2, 0};
  }
  pegasus::heli::SetPoint target(double) const override { return {}; }
};

std::size_t count(const std::string& text, char c) {
  std::size_t n = 0;
  for (char x : text) n += x == c;
  return n;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;  // fmemopen needs a buffer
  std::string input(pegasus::fuzz::as_text(data, size));
  std::FILE* in = fmemopen(input.data(), input.size(), "r");
  char* out_text = nullptr;
  char* err_text = nullptr;
  std::size_t out_size = 0, err_size = 0;
  std::FILE* out = open_memstream(&out_text, &out_size);
  std::FILE* err = open_memstream(&err_text, &err_size);
  if (in == nullptr || out == nullptr || err == nullptr) std::abort();
  const FixedController controller;
  pegasus::heli::ControlLoopStats served;
  try {  // a line server answers every line and never stops on one
    served = pegasus::heli::run_control_loop(controller, {0, 0, 0, 0}, in, out, err);
  } catch (const std::exception& e) {
    pegasus::fuzz::violation("an exception from the control loop", e.what());
  }
  std::fclose(in);
  std::fclose(out);
  std::fclose(err);
  const std::string answers(out_text, out_size), errors(err_text, err_size);
  std::free(out_text);
  std::free(err_text);
  const std::size_t lines = count(input, '\n') + (input.back() != '\n' ? 1 : 0);
  if (static_cast<std::size_t>(served.lines) != lines)
    pegasus::fuzz::violation("lines read", std::to_string(served.lines));
  if (count(answers, '\n') != lines || answers.back() != '\n')
    pegasus::fuzz::violation("not one answer line per input line", answers);
  // One stderr line per malformed line, and one about a header that was refused or had columns ignored.
  if (count(errors, '\n') != static_cast<std::size_t>(served.malformed + served.header_notes))
    pegasus::fuzz::violation("not one stderr line per malformed line", errors);
  if (!served.header_refused.empty() && served.malformed != served.lines - 1 - served.resets)
    pegasus::fuzz::violation("a line served under a refused header", answers);
  for (std::size_t start = 0; start < errors.size(); start = errors.find('\n', start) + 1) {
    if (errors.compare(start, 6, "stdin:") != 0)
      pegasus::fuzz::violation("a stderr line that names no line", errors);
  }
  return 0;
}
