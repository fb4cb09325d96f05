#pragma once
// A fresh empty folder for the running test, named by the process and the test so that tests run in parallel
// (ctest -j) never share one.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>
#include <string_view>

namespace pegasus::test_support {

inline std::filesystem::path fresh_test_dir(std::string_view prefix) {
  const auto* info = testing::UnitTest::GetInstance()->current_test_info();
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() /
      (std::string(prefix) + std::to_string(::getpid()) + "_" + info->test_suite_name() + "_" + info->name());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

}  // namespace pegasus::test_support
