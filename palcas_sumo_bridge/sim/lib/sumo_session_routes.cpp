// SumoSession: exit routing (a controlled CAV is routed to its own off-ramp once it can take
// it) and the on-ramp CAVs' own merge.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "palcas_sim/sumo_session.h"
#include "sumo_session_api.h"

namespace palcas::sim {

using namespace session_detail;

bool SumoSession::routeToOwnExit(VehicleRecord& v) {
  std::vector<std::string> edges;
  try {
    edges = api::Route::getEdges(v.route_id);
  } catch (const libsumo::TraCIException&) {
    return false;
  }
  auto here = std::find(edges.begin(), edges.end(), v.edge);
  if (here == edges.end()) return false;
  try {
    api::Vehicle::setRoute(v.id, std::vector<std::string>(here, edges.end()));
  } catch (const libsumo::TraCIException&) {
    ++route_changes_failed_;
    return false;
  }
  return true;
}

void SumoSession::manageExit(VehicleRecord& v) {
  if (v.exit_cluster < 0 || v.part == RoadPart::kOffRamp) return;
  auto it = pre_exit_edge_.find(v.exit_cluster);
  if (it == pre_exit_edge_.end() || v.edge != it->second) return;
  // On the edge feeding its off-ramp: commit to the exit while in lane 1, withdraw when it
  // leaves lane 1 (the off-ramp only connects from lane 1).
  const bool in_exit_lane = v.lane == 1;
  if (traceCommands() && in_exit_lane != v.exit_committed)
    std::fprintf(stderr, "[sumo t=%.1f] %s %s edge=%s lane=%d pos=%.2f\n", time_s_,
                 in_exit_lane ? "commit-exit" : "withdraw-exit", v.id.c_str(), v.edge.c_str(),
                 v.sumo_lane_index, v.lane_pos_m);
  // SUMO can refuse a route change ("No route found", e.g. a vehicle already past the
  // branch point mid lane change): the vehicle keeps the route it has, the refusal is
  // counted, and the simulation goes on (it once ended a whole training episode).
  try {
    if (in_exit_lane && !v.exit_committed) {
      // An explicit two-edge route: SUMO's router (changeTarget) finds no route to the
      // dead-end ramp edge, but the direct connection from lane 1 exists.
      api::Vehicle::setRoute(v.id, std::vector<std::string>{v.edge, road_->clusters()[v.exit_cluster].off_ramp_edge});
      v.exit_committed = true;
    } else if (!in_exit_lane && v.exit_committed) {
      api::Vehicle::changeTarget(v.id, end_edge_);
      v.exit_committed = false;
    }
  } catch (const libsumo::TraCIException& e) {
    if (route_changes_failed_++ == 0)
      std::fprintf(stderr, "palcas sim: t=%.1f s: SUMO refused a route change of '%s' (%s); it keeps "
                   "its route (counted in route_changes_failed, reported once)\n", time_s_, v.id.c_str(), e.what());
  }
}

void SumoSession::updateMergeMode(VehicleRecord& v) {
  // Strategic changes only until the CAV is on a mainline lane: from then on lane changes
  // (exits included) are the RSUs' job.
  if (v.part != RoadPart::kMainline || v.lane < 1) return;
  api::Vehicle::setLaneChangeMode(v.id, options_.cav_lane_change_mode);
  v.merge_mode = false;
}

}  // namespace palcas::sim
