// The files a config's fields name, relative to its base directory (runs/config.hpp: get_path).
#include <filesystem>
#include <string>
#include <vector>

#include "pegasus/runs/config.hpp"

namespace pegasus {

namespace fs = std::filesystem;

std::string path_under(const fs::path& base, const std::string& file) {
  if (base.empty() || file.empty() || fs::path(file).is_absolute()) return file;
  return (base / file).string();
}

std::string path_named_from(const fs::path& base, const std::string& path) {
  if (base.empty()) return path;
  const fs::path p(path);
  // Element by element: the base "/a/b" is no prefix of "/a/bc/x".
  auto at = p.begin();
  for (const fs::path& part : base) {
    if (part.empty()) continue;  // a trailing separator
    if (at == p.end() || *at != part) return path;
    ++at;
  }
  fs::path rest;
  for (; at != p.end(); ++at) rest /= *at;
  return rest.empty() ? path : rest.string();
}

std::string ConfigSchema::get_path(std::string_view name) const {
  return path_under(base_directory_, get_string(name));
}

std::vector<std::string> ConfigSchema::get_path_list(std::string_view name) const {
  std::vector<std::string> files = get_string_list(name);
  for (std::string& file : files) file = path_under(base_directory_, file);
  return files;
}

}  // namespace pegasus
