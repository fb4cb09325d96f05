// The helicopter pipeline (pilot logs, identification, hover training, flights against the pilot) run from a
// program: pegasus::cli::call_command runs the CLI's `heli pipeline` in this process, its settings given by
// their TOML names, and writes the same run directory. Small settings: a few seconds.
//   run_pipeline OUT_DIR
#include <cstdint>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <pegasus/cli/command.hpp>
#include <string>
#include <utility>
#include <vector>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: run_pipeline OUT_DIR\n";
    return 2;
  }
  const std::string out_dir = argv[1];
  const std::vector<std::pair<std::string, pegasus::FieldValue>> settings = {
      {"train_seconds", 60.0},        {"test_seconds", 25.0},    {"cv_points", std::int64_t{40}},
      {"scenarios", std::int64_t{2}}, {"scenario_seconds", 2.0}, {"gradient_iterations", std::int64_t{0}},
      {"flights", std::int64_t{2}},   {"flight_seconds", 3.0},   {"seed", std::int64_t{5}}};
  try {
    const int code = pegasus::cli::call_command("heli pipeline", settings, out_dir, {}, std::cout, std::cerr);
    if (code != 0) return code;
  } catch (const std::exception& e) {  // a bad setting: one line naming it
    std::cerr << e.what() << "\n";
    return 2;
  }
  const nlohmann::json summary = nlohmann::json::parse(std::ifstream(out_dir + "/summary.json"));
  std::cout << "flights " << summary.at("flights") << ", crashes " << summary.at("crashes") << "\n";
  return 0;
}
