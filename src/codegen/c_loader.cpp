#include "pegasus/codegen/c_loader.hpp"

#include <dlfcn.h>
#include <fmt/format.h>

#include <cstdio>
#include <stdexcept>

#include "pegasus/io/atomic_file.hpp"

namespace pegasus::codegen {

LoadedCPolicy::LoadedCPolicy(const CPolicyCode& code, const std::filesystem::path& dir,
                             const std::string& compiler) {
  std::filesystem::create_directories(dir);
  write_file_atomic(dir / code.header_name, code.header);
  write_file_atomic(dir / code.source_name, code.source);
  const std::filesystem::path library = dir / (code.source_name + ".so");
  command_ = fmt::format("{} {} -fPIC -shared -o '{}' '{}' -lm", compiler, kCFlags, library.string(),
                         (dir / code.source_name).string());
  std::string output;
  FILE* pipe = popen((command_ + " 2>&1").c_str(), "r");
  if (!pipe) throw std::runtime_error("cannot run " + command_);
  char buffer[4096];
  while (std::fgets(buffer, sizeof buffer, pipe)) output += buffer;
  if (pclose(pipe) != 0) throw std::runtime_error(fmt::format("{} failed:\n{}", command_, output));
  handle_ = dlopen(library.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!handle_) throw std::runtime_error(fmt::format("dlopen {}: {}", library.string(), dlerror()));
  const std::string prefix = code.source_name.substr(0, code.source_name.size() - 2);
  void* const act = dlsym(handle_, (prefix + "_act").c_str());
  void* const act_vehicle =
      code.vehicle_action_names.empty() ? nullptr : dlsym(handle_, (prefix + "_act_vehicle").c_str());
  // The generated prototypes take the generated struct's pointer; Memory* has the same representation.
  if (code.has_memory) {
    act_flight_ = reinterpret_cast<ActFlight>(act);
    act_vehicle_flight_ = reinterpret_cast<ActFlight>(act_vehicle);
    reset_ = reinterpret_cast<Reset>(dlsym(handle_, (prefix + "_reset").c_str()));
  } else {
    act_ = reinterpret_cast<Act>(act);
    act_vehicle_ = reinterpret_cast<Act>(act_vehicle);
  }
  if (code.has_target) target_ = reinterpret_cast<Target>(dlsym(handle_, (prefix + "_target").c_str()));
  if (!act || (code.has_target && !target_) || (!code.vehicle_action_names.empty() && !act_vehicle) ||
      (code.has_memory && !reset_)) {
    dlclose(handle_);
    throw std::runtime_error(fmt::format("{}: the generated functions are missing", library.string()));
  }
}

LoadedCPolicy::~LoadedCPolicy() {
  if (handle_) dlclose(handle_);
}

}  // namespace pegasus::codegen
