// DSR and MSR on a road a user brought, checked against what SUMO itself says happened.
// config/scenarios/three_ramps: 3 km, 5 lanes, edge names of its own (exits numbered off_1..off_3 from
// 1, as motorway exits are), three on-ramps and three off-ramps, two ramps of two edges, four
// zones the ramps do not line up with, and two exits leaving at a shallow angle (junction
// lanes of 26 m, longer than the 20 m miss margin). SUMO-native runs on it in process with
// SUMO's tripinfo output, measured by the bridge's own code on the states it would publish
// (sessionOptionsFor, measureRules, EpisodeMeasure), as bridge_node does. Then, CAV by CAV:
//   exits   a CAV whose route ends on an off-ramp and that SUMO says arrived there has
//           EXIT_OK; one that arrived elsewhere has EXIT_MISSED; one still on the road at the
//           end is censored unless SUMO has it on its off-ramp (or the junction lane onto it);
//   merges  a CAV from an on-ramp that SUMO says arrived has MERGE_OK; one still on the
//           road is censored unless SUMO has it off its ramp and acceleration lane;
// and exits_ok / exiting_cavs / merges_ok / merging_cavs (and the censored counts) are those
// numbers exactly. Before the fix this road scored DSR 0 % where tripinfo says 100 %.
// One libsumo simulation per process: one test starts SUMO. About 15 s.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "palcas_sim/scenario.h"
#include "palcas_sim/sumo_session.h"
#include "palcas_sumo_bridge/episode_measure.h"
#include "palcas_sumo_bridge/msg_conversion.h"
#include "palcas_sumo_bridge/run_files.h"

namespace palcas::bridge {
namespace {

namespace fs = std::filesystem;
using metrics::VehicleEventKind;

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path);
  std::ostringstream out;
  out << in.rdbuf();
  return out.str();
}

/// Every <tag .../> element of `text` as its attributes.
std::vector<std::map<std::string, std::string>> elements(const std::string& text, const std::string& tag) {
  std::vector<std::map<std::string, std::string>> out;
  const std::regex element("<" + tag + "\\s([^>]*)>");
  const std::regex attribute("([\\w.:-]+)=\"([^\"]*)\"");
  for (auto e = std::sregex_iterator(text.begin(), text.end(), element); e != std::sregex_iterator(); ++e) {
    const std::string body = (*e)[1];
    std::map<std::string, std::string> attrs;
    for (auto a = std::sregex_iterator(body.begin(), body.end(), attribute); a != std::sregex_iterator(); ++a)
      attrs[(*a)[1]] = (*a)[2];
    out.push_back(attrs);
  }
  return out;
}

std::string edgeOfLane(const std::string& lane) { return lane.substr(0, lane.rfind('_')); }

/// The road's scenario.yaml, read for the keys this test uses (the bridge reads it through the
/// parameter server, which a plain gtest has not).
sim::ScenarioConfig threeRampsConfig() {
  const std::string dir = std::string(PALCAS_CONFIG_DIR) + "/scenarios/three_ramps";
  const std::string yaml = slurp(dir + "/scenario.yaml");
  auto value = [&](const std::string& key) {
    std::smatch m;
    if (!std::regex_search(yaml, m, std::regex("\\n\\s*" + key + ":\\s*([^#\\s]+)")))
      throw std::runtime_error("scenario.yaml has no " + key);
    return m[1].str();
  };
  sim::ScenarioConfig c;
  c.scenario_dir = dir;
  c.network_file = value("network_file");
  c.road.clusters = std::stoi(value("clusters"));
  c.road.num_lanes = std::stoi(value("num_lanes"));
  c.mainline_flow_vphpl = std::stod(value("mainline_flow_vphpl"));
  c.onramp_flow_vphpl = std::stod(value("onramp_flow_vphpl"));
  return c;
}

/// What the bridge's measure said of one vehicle.
struct Measured {
  bool is_cav = false;
  std::set<VehicleEventKind> events;
  bool on_road_at_end = false;
  std::string lane_at_end;  ///< SUMO's lane id at the end (still on the road)
};

TEST(OwnRoadOutcomes, DsrAndMsrAgreeWithSumosTripinfo) {
  BridgeOptions o;  // the compiled-in defaults are config/bridge.yaml's (config_files.test)
  o.scenario = threeRampsConfig();
  o.scenario.duration_s = 400.0;
  o.scenario.seed = 3;
  o.scenario.penetration_rate = 0.6;
  o.out_dir = (fs::temp_directory_path() / ("palcas_own_road_outcomes_" + std::to_string(getpid()))).string();
  fs::remove_all(o.out_dir);
  o.sumo_outputs = {"tripinfo"};
  o.session.advisory_control = false;  // SUMO-native: SUMO's own models drive every vehicle
  const std::string sumocfg = prepareScenario(o);

  std::map<std::string, Measured> measured;
  metrics::EpisodeMetrics m;
  std::vector<metrics::ExitTally> exits;
  MeasureRules rules;
  {
    sim::SumoSession session(sessionOptionsFor(o, sumocfg, 0));
    ASSERT_EQ(session.road().clusters().size(), 4u);
    rules = measureRules(o, session.road());
    EpisodeMeasure measure(rules);
    palcas_msgs::VehicleStateArray states;
    const int steps = static_cast<int>(o.scenario.duration_s / o.scenario.step_length_s + 0.5);
    for (int step = 0; step < steps; ++step) {
      session.step();
      states.header.stamp = ros::Time(session.timeS());
      states.vehicles.clear();
      for (const sim::VehicleRecord& v : session.vehicles()) states.vehicles.push_back(toMsg(v));
      const auto& removed = session.lastEvents();
      for (const metrics::VehicleEvent& e :
           measure.onStep(states, {removed.collided, removed.teleported, removed.arrived})) {
        Measured& seen = measured[e.vehicle_id];
        seen.is_cav = e.is_cav;
        seen.events.insert(e.kind);
      }
    }
    for (const sim::VehicleRecord& v : session.vehicles()) {
      measured[v.id].on_road_at_end = true;
      measured[v.id].lane_at_end = v.edge + "_" + std::to_string(v.sumo_lane_index);
    }
    m = measure.metrics().snapshot();
    exits = measure.cavExits();
  }  // SUMO closes: the tripinfo file is complete

  // What SUMO drove: routes and flows, the network's connections, the trips it finished.
  const std::string routes_xml = slurp(o.out_dir + "/scenario/routes.rou.xml");
  std::map<std::string, std::vector<std::string>> route_edges;
  for (auto& r : elements(routes_xml, "route")) {
    std::istringstream edges(r["edges"]);
    for (std::string e; edges >> e;) route_edges[r["id"]].push_back(e);
  }
  std::map<std::string, std::string> flow_route;
  for (auto& f : elements(routes_xml, "flow")) flow_route[f["id"]] = f["route"];
  const std::vector<std::string>& through = route_edges.at("r_main_end");
  const std::set<std::string> mainline(through.begin(), through.end());
  auto routeOf = [&](const std::string& vehicle) -> const std::vector<std::string>& {
    return route_edges.at(flow_route.at(vehicle.substr(0, vehicle.rfind('.'))));
  };
  // Lanes a vehicle is on its way onto an edge through (junction lanes), and the lanes an
  // on-ramp feeds (its acceleration lane), from the network's connections.
  std::map<std::string, std::set<std::string>> lanes_onto, fed_by;
  for (auto& c : elements(slurp(o.out_dir + "/scenario/network.net.xml"), "connection")) {
    if (!c["via"].empty()) lanes_onto[c["to"]].insert(c["via"]);
    fed_by[c["from"]].insert(c["to"] + "_" + c["toLane"]);
    if (!c["via"].empty()) fed_by[c["from"]].insert(c["via"]);
  }

  int exit_ok = 0, exit_missed = 0, exit_removed = 0, exit_ok_on_road = 0, exit_decided_on_road = 0,
      exit_censored = 0;
  int merged = 0, merge_removed = 0, merged_on_road = 0, merge_censored = 0;
  std::vector<std::string> disagree;
  auto check = [&](bool agrees, const std::string& id, const std::string& what) {
    if (!agrees && disagree.size() < 12) disagree.push_back(id + ": " + what);
  };
  std::set<std::string> finished, ramps_taken;
  // Per exit (cluster of the route's off-ramp): served by SUMO's account, and still open.
  std::map<int, std::size_t> served_by_exit, censored_by_exit;
  auto exitOf = [&](const std::vector<std::string>& route) { return rules.off_ramp_edges.at(route.back()); };
  for (auto& t : elements(slurp(o.out_dir + "/sumo_tripinfo.xml"), "tripinfo")) {
    const std::string& id = t["id"];
    finished.insert(id);
    if (t["vType"].rfind("cav", 0) != 0) continue;  // a type whose id starts with cav is a CAV
    const std::vector<std::string>& route = routeOf(id);
    const Measured& seen = measured[id];
    const bool removed = !t["vaporized"].empty();  // a collision or a teleport ended its trip
    const std::string arrived_on = edgeOfLane(t["arrivalLane"]);
    if (!mainline.count(route.back())) {  // its route ends on an off-ramp
      const bool ok = seen.events.count(VehicleEventKind::kExitOk) > 0;
      const bool missed = seen.events.count(VehicleEventKind::kExitMissed) > 0;
      if (removed) {
        ++exit_removed;
        check(!ok, id, "removed (" + t["vaporized"] + ") before its exit, measured as taken");
      } else if (arrived_on == route.back()) {
        ++exit_ok;
        ++served_by_exit[exitOf(route)];
        ramps_taken.insert(arrived_on);
        check(ok && !missed, id, "arrived on its off-ramp " + route.back() + ", measured " +
                                     (missed ? "missed" : "undecided"));
      } else {
        ++exit_missed;
        check(missed && !ok, id, "arrived on " + arrived_on + ", not its off-ramp, measured taken");
      }
    }
    if (!mainline.count(route.front())) {  // from an on-ramp
      const bool ok = seen.events.count(VehicleEventKind::kMergeOk) > 0;
      if (removed) {
        ++merge_removed;
      } else {
        ++merged;  // it arrived, at the mainline's end or an off-ramp: it merged
        check(ok, id, "arrived (on " + arrived_on + ") from an on-ramp, merge measured as failed");
      }
    }
  }
  // Still on the road when the run ended: SUMO's own lane says where.
  for (const auto& [id, seen] : measured) {
    if (!seen.on_road_at_end || finished.count(id) || !seen.is_cav) continue;
    const std::vector<std::string>& route = routeOf(id);
    const std::string& lane = seen.lane_at_end;
    if (!mainline.count(route.back())) {
      const std::string& ramp = route.back();
      const bool sumo_on_ramp = edgeOfLane(lane) == ramp || lanes_onto[ramp].count(lane) > 0;
      const bool ok = seen.events.count(VehicleEventKind::kExitOk) > 0;
      const bool missed = seen.events.count(VehicleEventKind::kExitMissed) > 0;
      exit_ok_on_road += ok;
      exit_decided_on_road += ok || missed;
      exit_censored += !ok && !missed;
      served_by_exit[exitOf(route)] += ok;
      censored_by_exit[exitOf(route)] += !ok && !missed;
      check(ok == sumo_on_ramp && !missed, id,
            "on " + lane + " at the end, measured " + (ok ? "taken" : missed ? "missed" : "undecided"));
    }
    if (!mainline.count(route.front())) {
      // On its on-ramp's edges, on a lane they feed (junction lanes, the acceleration lane).
      bool sumo_merging = false;
      for (auto e = route.begin(); e != route.end() && !mainline.count(*e); ++e)
        sumo_merging = sumo_merging || edgeOfLane(lane) == *e || fed_by[*e].count(lane) > 0;
      const bool ok = seen.events.count(VehicleEventKind::kMergeOk) > 0;
      const bool failed = seen.events.count(VehicleEventKind::kMergeFailed) > 0;
      merged_on_road += ok;
      merge_censored += !ok && !failed;
      check(ok == !sumo_merging && !failed, id,
            "on " + lane + " at the end, merge measured " + (ok ? "done" : failed ? "failed" : "undecided"));
    }
  }
  std::string listed;
  for (const std::string& d : disagree) listed += "\n  " + d;
  EXPECT_TRUE(disagree.empty()) << "the measure disagrees with SUMO on these CAVs:" << listed;

  // A run that says something: every exit and on-ramp used, CAVs on each side of the end.
  EXPECT_GT(exit_ok, 60) << "CAVs that took their off-ramp";
  EXPECT_GT(merged, 40) << "CAVs that merged";
  EXPECT_GT(exit_censored, 0) << "exit-bound CAVs still before their exit at the end";
  EXPECT_EQ(ramps_taken.size(), 3u) << "off-ramps CAVs arrived on";

  // The metrics are those numbers exactly: DSR and MSR over the CAVs whose outcome is decided.
  EXPECT_EQ(m.exits_ok, static_cast<std::uint64_t>(exit_ok + exit_ok_on_road));
  EXPECT_EQ(m.exiting_cavs,
            static_cast<std::uint64_t>(exit_ok + exit_missed + exit_removed + exit_decided_on_road));
  EXPECT_EQ(m.exiting_cavs_censored, static_cast<std::uint64_t>(exit_censored));
  EXPECT_EQ(m.merges_ok, static_cast<std::uint64_t>(merged + merged_on_road));
  EXPECT_EQ(m.merging_cavs, static_cast<std::uint64_t>(merged + merge_removed + merged_on_road));
  EXPECT_EQ(m.merging_cavs_censored, static_cast<std::uint64_t>(merge_censored));
  // Each exit's tally is SUMO's account of that exit's CAVs (the three with an off-ramp).
  ASSERT_EQ(exits.size(), 4u);
  for (int k = 0; k < 4; ++k) {
    EXPECT_EQ(exits[k].served, served_by_exit[k]) << "exit " << k;
    EXPECT_EQ(exits[k].censored, censored_by_exit[k]) << "exit " << k;
  }
  EXPECT_EQ(std::count_if(served_by_exit.begin(), served_by_exit.end(), [](const auto& e) { return e.second > 0; }),
            3) << "exits whose CAVs SUMO delivered";
  // SUMO-native drives every CAV along its route: tripinfo has every arrived exit on its ramp.
  EXPECT_EQ(exit_missed, 0);
  EXPECT_DOUBLE_EQ(m.dsr_pct, 100.0 * m.exits_ok / m.exiting_cavs);
  std::cout << "three_ramps, SUMO-native, " << static_cast<int>(o.scenario.duration_s) << " s: tripinfo " << exit_ok << " of "
            << exit_ok + exit_missed + exit_removed << " arrived exit-bound CAVs on their off-ramp; measured DSR "
            << m.dsr_pct << " % (" << m.exits_ok << " of " << m.exiting_cavs << ", " << m.exiting_cavs_censored
            << " censored), MSR " << m.msr_pct << " % (" << m.merges_ok << " of " << m.merging_cavs << ")\n";
  fs::remove_all(o.out_dir);
}

}  // namespace
}  // namespace palcas::bridge
