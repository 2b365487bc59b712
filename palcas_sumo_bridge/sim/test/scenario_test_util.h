#pragma once
// Helpers shared by the scenario tests: a fresh temporary folder per test and file reading.

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace palcas::sim::test {

/// A new empty folder under the system temp dir, unique per process and name.
inline std::string freshDir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("palcas_scenario_" + std::to_string(getpid()) + "_" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

inline std::string scenarioDir(const std::string& name) {
  return std::string(PALCAS_CONFIG_DIR) + "/scenarios/" + name;
}

inline std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream out;
  out << in.rdbuf();
  return out.str();
}

}  // namespace palcas::sim::test
