#include "palcas_core/common/build_info.h"

#include <Eigen/Core>

#include <fstream>

#ifndef PALCAS_CORE_ARCH
#error "PALCAS_CORE_ARCH is set by src/CMakeLists.txt"
#endif

namespace palcas {
namespace {

std::string cpuModel() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("model name", 0) != 0) continue;
    const auto colon = line.find(':');
    if (colon == std::string::npos) break;
    const auto start = line.find_first_not_of(" \t", colon + 1);
    return start == std::string::npos ? "unknown" : line.substr(start);
  }
  return "unknown";
}

}  // namespace

BuildInfo buildInfo() { return {PALCAS_CORE_ARCH, Eigen::SimdInstructionSetsInUse(), cpuModel()}; }

}  // namespace palcas
