#pragma once
// Generated C (c_policy.hpp) compiled into a shared object and loaded into this process: how the tests check
// the bit-identity guarantee and the benchmark times the exported controller, compiled exactly as a flight
// computer's build would compile it (kCFlags; no -march, so no FMA on x86-64).
#include <filesystem>
#include <string>

#include "pegasus/codegen/c_policy.hpp"

namespace pegasus::codegen {

// The warnings the generated code must pass, and an operation order that matches the library's build.
inline constexpr const char* kCFlags = "-std=c99 -Wall -Wextra -Werror -pedantic -O3 -ffp-contract=off";

class LoadedCPolicy {
 public:
  using Act = int (*)(const double* observation, double* action);
  using Target = int (*)(double time, double* set_point);
  // A controller with memory (CPolicyCode::has_memory): its PREFIX_act and PREFIX_act_vehicle take the
  // flight's PREFIX_memory first; Memory holds one (the generated struct is far smaller).
  struct Memory {
    alignas(16) unsigned char bytes[256];
  };
  using ActFlight = int (*)(Memory* memory, const double* observation, double* action);
  using Reset = void (*)(Memory* memory);

  // Writes the code into `dir` (created), compiles it with `compiler` (kCFlags -fPIC -shared ... -lm) and
  // loads it. std::runtime_error with the compiler's output when it does not compile or load.
  LoadedCPolicy(const CPolicyCode& code, const std::filesystem::path& dir,
                const std::string& compiler = "gcc");
  ~LoadedCPolicy();
  LoadedCPolicy(const LoadedCPolicy&) = delete;
  LoadedCPolicy& operator=(const LoadedCPolicy&) = delete;

  Act act() const { return act_; }                  // nullptr for a controller with memory
  Target target() const { return target_; }         // nullptr for classes without a set point
  Act act_vehicle() const { return act_vehicle_; }  // nullptr without a vehicle (or with memory)
  // A controller with memory's (nullptr otherwise).
  ActFlight act_flight() const { return act_flight_; }
  ActFlight act_vehicle_flight() const { return act_vehicle_flight_; }
  Reset reset() const { return reset_; }
  const std::string& compile_command() const { return command_; }

 private:
  void* handle_ = nullptr;
  Act act_ = nullptr;
  Target target_ = nullptr;
  Act act_vehicle_ = nullptr;
  ActFlight act_flight_ = nullptr, act_vehicle_flight_ = nullptr;
  Reset reset_ = nullptr;
  std::string command_;
};

}  // namespace pegasus::codegen
