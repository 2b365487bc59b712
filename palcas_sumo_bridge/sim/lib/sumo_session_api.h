#pragma once
// What the parts of SumoSession (sumo_session*.cpp) share: SUMO's C++ API, chosen at compile
// time, and the small TraCI decoding helpers. Private to palcas_sim's session sources: each
// of them is compiled twice, against libsumo (SUMO in-process) and with PALCAS_USE_LIBTRACI
// against libtraci (a client of an external sumo / sumo-gui). LIBSUMO_NAMESPACE names the
// API namespace in both cases; the result types stay in namespace libsumo.
#ifdef PALCAS_USE_LIBTRACI
#include <libsumo/libtraci.h>
#else
#include <libsumo/libsumo.h>
#endif

#include <cctype>
#include <cstdlib>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace palcas::sim {
namespace api = LIBSUMO_NAMESPACE;

namespace session_detail {

inline constexpr double INF = std::numeric_limits<double>::infinity();

// Every variable SUMO builds for every vehicle every step costs time, so the list is short:
// the lane id carries edge and lane index, and the heading (only for drawing) comes from
// successive positions.
inline const std::vector<int>& vehicleVariables() {
  static const std::vector<int> vars = {
      libsumo::VAR_POSITION,  libsumo::VAR_SPEED,        libsumo::VAR_ACCELERATION,
      libsumo::VAR_SPEED_LAT, libsumo::VAR_LANE_ID,      libsumo::VAR_LANEPOSITION,
      libsumo::VAR_LANEPOSITION_LAT};
  return vars;
}

/// "<edge>_<index>" (internal lanes ":<junction>_<n>_<index>") into edge and index.
inline void splitLaneId(const std::string& lane_id, std::string* edge, int* index) {
  const std::size_t cut = lane_id.rfind('_');
  if (cut == std::string::npos) {
    *edge = lane_id;
    *index = -1;
    return;
  }
  *edge = lane_id.substr(0, cut);
  *index = std::atoi(lane_id.c_str() + cut + 1);
}

inline double asDouble(const libsumo::TraCIResults& r, int var) {
  auto it = r.find(var);
  if (it == r.end()) return std::numeric_limits<double>::quiet_NaN();
  if (auto d = std::dynamic_pointer_cast<libsumo::TraCIDouble>(it->second)) return d->value;
  if (auto i = std::dynamic_pointer_cast<libsumo::TraCIInt>(it->second)) return i->value;
  return std::numeric_limits<double>::quiet_NaN();
}

inline std::string asString(const libsumo::TraCIResults& r, int var) {
  auto it = r.find(var);
  if (it == r.end()) return {};
  if (auto s = std::dynamic_pointer_cast<libsumo::TraCIString>(it->second)) return s->value;
  return {};
}

inline std::vector<std::string> asStringList(const libsumo::TraCIResults& r, int var) {
  auto it = r.find(var);
  if (it == r.end()) return {};
  if (auto s = std::dynamic_pointer_cast<libsumo::TraCIStringList>(it->second)) return s->value;
  return {};
}

inline int clusterSuffix(const std::string& s, const std::string& prefix) {
  if (s.compare(0, prefix.size(), prefix) != 0 || s.size() == prefix.size()) return -2;
  for (std::size_t i = prefix.size(); i < s.size(); ++i)
    if (!std::isdigit(static_cast<unsigned char>(s[i]))) return -2;
  return std::stoi(s.substr(prefix.size()));
}

/// PALCAS_TRACE_SUMO=1: every lane-change and route command on stderr (for SUMO bugs).
inline bool traceCommands() {
  static const bool on = std::getenv("PALCAS_TRACE_SUMO") != nullptr;
  return on;
}

}  // namespace session_detail
}  // namespace palcas::sim
