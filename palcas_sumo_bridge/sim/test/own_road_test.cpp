// A user's own road (own_road.h): config/scenarios/curved (a curved mainline, an on-ramp with
// an acceleration lane, an off-ramp about 760 m after it, a lane drop 5 -> 4, edge names of its own)
// built with netconvert from its sources, the road found in it, its routes; and the errors a
// user gets for a road that does not fit.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "common/throws_naming.h"
#include "palcas_sim/own_road.h"
#include "palcas_sim/scenario.h"
#include "scenario_test_util.h"

// The error's type and a piece of its text (the suite's rule for bad input).
#define EXPECT_THROW_NAMING(call, E, needle) palcas_test::expectThrowNaming<E>([&] { (void)(call); }, needle)

namespace palcas::sim {
namespace {

using test::freshDir;
using test::scenarioDir;
using test::slurp;

ScenarioConfig curvedConfig() {
  ScenarioConfig c;
  c.scenario_dir = scenarioDir("curved");
  c.network_file = "curved.netccfg";
  c.road.clusters = 2;
  c.road.num_lanes = 5;
  c.duration_s = 120.0;
  return c;
}

/// The curved road, built once for the whole test program.
const OwnRoad& curvedRoad() {
  static const OwnRoad road = [] {
    const ScenarioFiles files = writeScenario(curvedConfig(), freshDir("own_road_curved"));
    return discoverOwnRoad(readNetTopology(files.net_file), ownRoadOptions(curvedConfig()));
  }();
  return road;
}

const EdgeInfo& edgeOf(const OwnRoad& road, const std::string& id) {
  auto it = std::find_if(road.edges.begin(), road.edges.end(), [&](const EdgeInfo& e) { return e.id == id; });
  if (it == road.edges.end()) throw std::out_of_range("no edge " + id);
  return *it;
}

TEST(OwnRoad, FindsTheCurvedMainlineByTheRule) {
  const OwnRoad& road = curvedRoad();
  EXPECT_EQ(road.mainline, (std::vector<std::string>{"west_in", "weave", "bend", "straight", "narrow"}));
  EXPECT_EQ(road.num_main_lanes, 5);
  EXPECT_EQ(road.clusters, 2);
}

TEST(OwnRoad, PositionsRunAlongTheLanesThroughTheCurve) {
  const OwnRoad& road = curvedRoad();
  double x = 0.0;
  for (const std::string& id : road.mainline) {
    const EdgeInfo& e = edgeOf(road, id);
    EXPECT_GE(e.x_start_m, x) << id;          // monotone, junction lanes in between
    EXPECT_LT(e.x_start_m - x, 20.0) << id;   // and short
    EXPECT_GT(e.x_end_m, e.x_start_m) << id;
    x = e.x_end_m;
  }
  EXPECT_DOUBLE_EQ(road.mainline_length_m, x);
  // The bend is measured along its lanes (an arc of 25 degrees), longer than its chord.
  const EdgeInfo& bend = edgeOf(road, "bend");
  EXPECT_GT(bend.x_end_m - bend.x_start_m, 430.0);
  EXPECT_GT(road.mainline_length_m, 1700.0);
  EXPECT_LT(road.mainline_length_m, 1800.0);
  // Junction-internal edges are placed too: the one after the bend starts where it ends.
  bool internal_after_bend = false;
  for (const auto& [id, x_start] : road.internal_x_start_m)
    if (id.rfind(":gore_out", 0) == 0 && std::abs(x_start - bend.x_end_m) < 1e-9) internal_after_bend = true;
  EXPECT_TRUE(internal_after_bend);
}

TEST(OwnRoad, FindsRampsAccelerationLaneAndLaneDrop) {
  const OwnRoad& road = curvedRoad();
  const EdgeInfo& in = edgeOf(road, "slip_in");
  const EdgeInfo& out = edgeOf(road, "slip_out");
  const EdgeInfo& weave = edgeOf(road, "weave");
  EXPECT_EQ(in.part, RoadPart::kOnRamp);
  EXPECT_EQ(out.part, RoadPart::kOffRamp);
  EXPECT_TRUE(weave.has_accel_lane);
  EXPECT_EQ(weave.lane_count, 6);
  EXPECT_EQ(weave.cluster, in.cluster);
  EXPECT_FALSE(edgeOf(road, "bend").has_accel_lane);
  // The on-ramp ends where weave starts (less its junction lane); the off-ramp starts where
  // bend ends; both within 800 m of each other, in zones 0 and 1.
  EXPECT_NEAR(in.x_end_m, weave.x_start_m, 20.0);
  EXPECT_LE(in.x_end_m, weave.x_start_m);
  EXPECT_GE(out.x_start_m, edgeOf(road, "bend").x_end_m);  // after its junction lane
  EXPECT_NEAR(out.x_start_m, edgeOf(road, "bend").x_end_m, 20.0);
  EXPECT_LT(out.x_start_m - weave.x_start_m, 800.0);
  EXPECT_EQ(in.cluster, 0);
  EXPECT_EQ(out.cluster, 1);
  EXPECT_EQ(road.exit_from_edge.at(1), "bend");
  EXPECT_EQ(road.on_ramp_joins_edge.at(0), "weave");
  EXPECT_EQ(edgeOf(road, "narrow").lane_count, 4);
}

TEST(OwnRoad, LayoutMapsLanesAndPositionsAndZones) {
  const RoadLayout layout(curvedRoad());
  ASSERT_EQ(layout.clusters().size(), 2u);
  const double half = layout.mainlineLengthM() / 2.0;
  EXPECT_DOUBLE_EQ(layout.clusters()[0].x_end_m, half);
  EXPECT_DOUBLE_EQ(layout.clusters()[1].x_start_m, half);
  EXPECT_DOUBLE_EQ(layout.clusters()[1].x_end_m, layout.mainlineLengthM());
  const ClusterInfo& zone0 = layout.clusters()[0];
  EXPECT_EQ(zone0.on_ramp_edge, "slip_in");
  EXPECT_EQ(zone0.merge_edge, "weave");
  EXPECT_NEAR(zone0.accel_lane_length_m, 261.0, 1.0);
  EXPECT_TRUE(zone0.off_ramp_edge.empty());
  EXPECT_EQ(layout.clusters()[1].off_ramp_edge, "slip_out");
  EXPECT_DOUBLE_EQ(layout.clusters()[1].exit_x_m, layout.edge("bend").x_end_m);
  EXPECT_TRUE(layout.clusters()[1].on_ramp_edge.empty());
  // Paper lanes: weave's SUMO lane 0 is the acceleration lane; narrow has no lane 5.
  EXPECT_EQ(layout.paperLane("weave", 0), 0);
  EXPECT_EQ(layout.paperLane("weave", 1), 1);
  EXPECT_EQ(layout.paperLane("narrow", 3), 4);
  EXPECT_EQ(layout.sumoLaneIndex("narrow", 4), 3);
  EXPECT_EQ(layout.sumoLaneIndex("narrow", 5), -1);
  EXPECT_EQ(layout.sumoLaneIndex("straight", 5), 4);
  // The lanes an advisory may target there: the validator's one lane check.
  EXPECT_EQ(layout.mainLanesOn("narrow"), 4);
  EXPECT_EQ(layout.mainLanesOn("straight"), 5);
  EXPECT_EQ(layout.mainLanesOn("weave"), 5);
  EXPECT_EQ(layout.mainLanesOn("slip_in"), 5);
  EXPECT_EQ(layout.mainLanesOn("no_such_edge"), 5);
  EXPECT_EQ(layout.paperLane("slip_in", 0), 0);
  // x: edge offset + lane position; a ramp vehicle counts down to where it joins.
  const EdgeInfo& bend = layout.edge("bend");
  EXPECT_DOUBLE_EQ(layout.xAlongMainline("bend", 100.0, -1.0), bend.x_start_m + 100.0);
  EXPECT_LT(layout.xAlongMainline("slip_in", 0.0, -1.0), layout.xAlongMainline("slip_in", 50.0, -1.0));
  EXPECT_DOUBLE_EQ(layout.xAlongMainline("no_such_edge", 5.0, -1.0), -1.0);
  EXPECT_TRUE(layout.measuredAlongLanes());
  EXPECT_EQ(layout.mainline().front(), "west_in");
}

TEST(OwnRoad, RoutesUseTheRoadsOwnEdges) {
  const std::vector<RouteDemand> routes = buildOwnRoadRoutes(curvedConfig(), curvedRoad());
  std::map<std::string, RouteDemand> by_id;
  for (const RouteDemand& r : routes) by_id[r.id] = r;
  ASSERT_EQ(by_id.size(), 4u);
  using Edges = std::vector<std::string>;
  EXPECT_EQ(by_id.at("r_main_end").edges, (Edges{"west_in", "weave", "bend", "straight", "narrow"}));
  EXPECT_EQ(by_id.at("r_main_off1").edges, (Edges{"west_in", "weave", "bend", "slip_out"}));
  EXPECT_EQ(by_id.at("r_on0_end").edges, (Edges{"slip_in", "weave", "bend", "straight", "narrow"}));
  EXPECT_EQ(by_id.at("r_on0_off1").edges, (Edges{"slip_in", "weave", "bend", "slip_out"}));
  // Default shares over the ramps there are; the mainline flow over the first edge's 5 lanes.
  const ScenarioConfig c = curvedConfig();
  EXPECT_NEAR(by_id.at("r_main_end").vehs_per_hour, 0.55 * 5 * c.mainline_flow_vphpl, 1e-9);
  EXPECT_NEAR(by_id.at("r_main_off1").vehs_per_hour, 0.45 * 5 * c.mainline_flow_vphpl, 1e-9);
  EXPECT_NEAR(by_id.at("r_on0_off1").vehs_per_hour, 0.6 * c.onramp_flow_vphpl, 1e-9);
  EXPECT_TRUE(by_id.at("r_on0_end").from_ramp);
}

TEST(OwnRoad, AGivenMainlineIsUsedAndChecked) {
  const ScenarioFiles files = writeScenario(curvedConfig(), freshDir("own_road_given"));
  const NetTopology net = readNetTopology(files.net_file);
  OwnRoadOptions o;
  o.clusters = 2;
  o.mainline_edges = {"west_in", "weave", "bend", "straight", "narrow"};
  EXPECT_EQ(discoverOwnRoad(net, o).mainline, o.mainline_edges);
  o.mainline_edges = {"west_in", "weave", "bend", "no_such_edge"};
  EXPECT_THROW_NAMING(discoverOwnRoad(net, o), std::invalid_argument, "no edge 'no_such_edge'");
  o.mainline_edges = {"west_in", "bend"};
  EXPECT_THROW_NAMING(discoverOwnRoad(net, o), std::invalid_argument, "no lane of 'west_in' connects to 'bend'");
  o.mainline_edges = {};
  o.clusters = 0;
  EXPECT_THROW_NAMING(discoverOwnRoad(net, o), std::invalid_argument, "road/clusters must be >= 1");
}

TEST(OwnRoad, ScenarioErrorsNameWhatIsWrong) {
  ScenarioConfig c = curvedConfig();
  c.network_file = "missing.net.xml";
  EXPECT_THROW_NAMING(writeScenario(c, freshDir("own_road_missing")), std::invalid_argument,
                      "network_file 'missing.net.xml': no such file");
  c = curvedConfig();
  c.network_file = "curved.nod.xml";
  EXPECT_THROW_NAMING(writeScenario(c, freshDir("own_road_kind")), std::invalid_argument,
                      "neither a SUMO network (*.net.xml) nor a netconvert configuration");
  c = curvedConfig();
  c.road.num_lanes = 4;
  EXPECT_THROW_NAMING(writeScenario(c, freshDir("own_road_lanes")), std::invalid_argument,
                      "set road/num_lanes to 5");
  c = curvedConfig();
  c.road.clusters = 1;  // one zone then holds both ramps: one of each is allowed
  EXPECT_NO_THROW(writeScenario(c, freshDir("own_road_one_zone")));
  c = curvedConfig();
  c.network_file.clear();
  c.mainline_edges = {"west_in"};
  EXPECT_THROW_NAMING(validateScenarioConfig(c), std::invalid_argument, "only read with network_file");
}

TEST(OwnRoad, UserRouteFileGoesAfterTheVehicleTypes) {
  const std::string dir = freshDir("own_road_route_file_src");
  for (const auto& entry : std::filesystem::directory_iterator(scenarioDir("curved")))
    std::filesystem::copy(entry.path(), dir + "/" + entry.path().filename().string());
  {
    std::ofstream out(dir + "/mine.rou.xml");
    out << "<routes>\n  <route id=\"through\" edges=\"west_in weave bend straight narrow\"/>\n"
        << "  <flow id=\"mine\" route=\"through\" type=\"mixed\" begin=\"0\" end=\"60\" vehsPerHour=\"900\"/>\n</routes>\n";
  }
  ScenarioConfig c = curvedConfig();
  c.scenario_dir = dir;
  c.route_file = "mine.rou.xml";
  const ScenarioFiles files = writeScenario(c, freshDir("own_road_route_file"));
  const std::string routes = slurp(files.routes_file);
  EXPECT_NE(routes.find("<vTypeDistribution id=\"mixed\">"), std::string::npos);
  EXPECT_LT(routes.find("</vTypeDistribution>"), routes.find("<flow id=\"mine\""));
  EXPECT_EQ(routes.find("r_main_end"), std::string::npos);  // the user's routes instead of the demand's
  c.route_file = "absent.rou.xml";
  EXPECT_THROW_NAMING(writeScenario(c, freshDir("own_road_route_absent")), std::invalid_argument,
                      "route_file 'absent.rou.xml': no such file");
}

TEST(OwnRoad, ANetXmlIsUsedAsItIs) {
  // The network netconvert built from the sources, brought as a .net.xml instead.
  const std::string dir = freshDir("own_road_net_xml_src");
  const ScenarioFiles built = writeScenario(curvedConfig(), freshDir("own_road_net_xml_built"));
  std::filesystem::copy(built.net_file, dir + "/mine.net.xml");
  std::filesystem::copy(scenarioDir("curved") + "/vtypes.xml", dir + "/vtypes.xml");
  ScenarioConfig c = curvedConfig();
  c.scenario_dir = dir;
  c.network_file = "mine.net.xml";
  const ScenarioFiles files = writeScenario(c, freshDir("own_road_net_xml"));
  EXPECT_EQ(slurp(files.net_file), slurp(built.net_file));
  const OwnRoad road = discoverOwnRoad(readNetTopology(files.net_file), ownRoadOptions(c));
  EXPECT_EQ(road.mainline, curvedRoad().mainline);
  EXPECT_DOUBLE_EQ(road.mainline_length_m, curvedRoad().mainline_length_m);
}

ScenarioConfig threeRampsConfig() {
  ScenarioConfig c;
  c.scenario_dir = scenarioDir("three_ramps");
  c.network_file = "ring.netccfg";
  c.road.clusters = 4;
  c.road.num_lanes = 5;
  c.duration_s = 120.0;
  return c;
}

TEST(OwnRoad, ThreeRampsEachInTheZoneOfItsJunction) {
  // config/scenarios/three_ramps: exits numbered off_1..off_3 by their user, in zones 0, 1
  // and 3 of four (750 m each); entries in zones 0, 1 and 2.
  const ScenarioFiles files = writeScenario(threeRampsConfig(), freshDir("own_road_three_ramps"));
  const RoadLayout road(discoverOwnRoad(readNetTopology(files.net_file), ownRoadOptions(threeRampsConfig())));
  ASSERT_EQ(road.clusters().size(), 4u);
  EXPECT_NEAR(road.mainlineLengthM(), 3000.0, 1.0);
  std::vector<std::string> on, off;
  for (const ClusterInfo& c : road.clusters()) {
    on.push_back(c.on_ramp_edge);
    off.push_back(c.off_ramp_edge);
  }
  EXPECT_EQ(on, (std::vector<std::string>{"entry_harbour", "entry_mall", "entry_park", ""}));
  EXPECT_EQ(off, (std::vector<std::string>{"off_1", "off_2", "", "off_3"}));
  // Near the zone boundaries: off_1 leaves 24 m before the first, off_3 56 m after the third.
  EXPECT_NEAR(road.clusters()[0].exit_x_m, 726.0, 1.0);
  EXPECT_NEAR(road.clusters()[3].exit_x_m, 2306.0, 1.0);

  // The junction lanes onto each off-ramp are that off-ramp's (off_1's and off_3's leave at a
  // shallow angle: 26 m, longer than the 20 m miss margin); those straight on are not.
  const std::map<std::string, int> off_ramps = road.offRampEdges();
  EXPECT_EQ(off_ramps.at("off_1"), 0);
  EXPECT_EQ(off_ramps.at("off_2"), 1);
  EXPECT_EQ(off_ramps.at("off_3"), 3);
  EXPECT_EQ(off_ramps.at(":harbour_exit_0"), 0);
  EXPECT_EQ(off_ramps.at(":mall_exit_0"), 1);
  EXPECT_EQ(off_ramps.at(":park_exit_0"), 3);
  EXPECT_EQ(off_ramps.count(":harbour_exit_1"), 0u);
  EXPECT_EQ(off_ramps.size(), 6u);
  EXPECT_EQ(off_ramps.count("mall_street"), 0u);  // the mall exit's second edge: not placed

  // A route's entry and exit are its ramps', whatever its id says.
  RouteKind kind = RouteKind::kMainThrough;
  int entry = -9, exit = -9;
  classifyRouteByEdges(road, {"mall_street_in", "entry_mall", "A1_mall_weave", "A1_mall", "A1_mall_park",
                              "A1_park_weave", "A1_park", "off_3"},
                       &kind, &entry, &exit);
  EXPECT_EQ(kind, RouteKind::kRampExit);
  EXPECT_EQ(entry, 1);
  EXPECT_EQ(exit, 3);
  classifyRouteByEdges(road, {"A1_west", "A1_harbour_weave", "A1_harbour", "off_1"}, &kind, &entry, &exit);
  EXPECT_EQ(kind, RouteKind::kMainExit);
  EXPECT_EQ(entry, -1);
  EXPECT_EQ(exit, 0);
  classifyRouteByEdges(road, {"A1_park", "A1_east"}, &kind, &entry, &exit);
  EXPECT_EQ(kind, RouteKind::kMainThrough);
  EXPECT_EQ(exit, -1);
}

TEST(OwnRoad, ZonesStartWhereTheUserSays) {
  // Three zones in equal thirds put the harbour and the mall entries both in zone 0: refused.
  // Where an operator would stand the three RSUs, one per junction pair, they fit, given as
  // edges or as x.
  ScenarioConfig c = threeRampsConfig();
  c.road.clusters = 3;
  const ScenarioFiles files = writeScenario(threeRampsConfig(), freshDir("own_road_zone_starts"));
  const NetTopology net = readNetTopology(files.net_file);
  EXPECT_THROW_NAMING(discoverOwnRoad(net, ownRoadOptions(c)), std::invalid_argument,
                      "zone 0 has two on-ramps ('entry_harbour' and 'entry_mall')");
  c.road.zone_start_edges = {"A1_west", "A1_harbour_mall", "A1_mall_park"};
  const OwnRoad by_edge = discoverOwnRoad(net, ownRoadOptions(c));
  const RoadLayout road(by_edge);
  ASSERT_EQ(road.clusters().size(), 3u);
  std::vector<std::string> on, off;
  for (const ClusterInfo& k : road.clusters()) {
    on.push_back(k.on_ramp_edge);
    off.push_back(k.off_ramp_edge);
  }
  EXPECT_EQ(on, (std::vector<std::string>{"entry_harbour", "entry_mall", "entry_park"}));
  EXPECT_EQ(off, (std::vector<std::string>{"off_1", "off_2", "off_3"}));
  const double mall_start = edgeOf(by_edge, "A1_harbour_mall").x_start_m;
  const double park_start = edgeOf(by_edge, "A1_mall_park").x_start_m;
  EXPECT_DOUBLE_EQ(road.clusters()[0].x_start_m, 0.0);
  EXPECT_DOUBLE_EQ(road.clusters()[0].x_end_m, mall_start);
  EXPECT_DOUBLE_EQ(road.clusters()[1].x_start_m, mall_start);
  EXPECT_DOUBLE_EQ(road.clusters()[2].x_start_m, park_start);
  EXPECT_DOUBLE_EQ(road.clusters()[2].x_end_m, road.mainlineLengthM());
  // The one zone lookup follows: the last metre before a start is the zone before it.
  EXPECT_EQ(road.zoneAt(mall_start - 1.0), 0);
  EXPECT_EQ(road.zoneAt(mall_start), 1);
  EXPECT_EQ(road.zoneAt(park_start + 1.0), 2);
  EXPECT_EQ(road.clusterAt(road.mainlineLengthM() + 50.0), 2);
  // The same zones by x.
  c.road.zone_start_edges.clear();
  c.road.zone_starts_m = {0.0, mall_start, park_start};
  EXPECT_EQ(discoverOwnRoad(net, ownRoadOptions(c)).zone_starts_m, by_edge.zone_starts_m);
  // And through the scenario, routes included.
  EXPECT_NO_THROW(writeScenario(c, freshDir("own_road_zone_starts_x")));
}

TEST(OwnRoad, ZoneStartsThatDoNotFitAreRefusedNamingTheKey) {
  const ScenarioFiles files = writeScenario(threeRampsConfig(), freshDir("own_road_zone_starts_bad"));
  const NetTopology net = readNetTopology(files.net_file);
  ScenarioConfig c = threeRampsConfig();
  c.road.clusters = 3;
  const auto refused = [&](const std::vector<double>& x, const std::vector<std::string>& edges, const char* needle) {
    ScenarioConfig bad = c;
    bad.road.zone_starts_m = x;
    bad.road.zone_start_edges = edges;
    EXPECT_THROW_NAMING(discoverOwnRoad(net, ownRoadOptions(bad)), std::invalid_argument, needle);
  };
  refused({0.0, 1000.0}, {}, "road/zone_starts_m lists 2 zones but road/clusters is 3: set road/clusters to 2");
  refused({5.0, 1000.0, 2000.0}, {}, "road/zone_starts_m[0] = 5");
  refused({0.0, 2000.0, 1000.0}, {}, "road/zone_starts_m[2] starts at 1000");
  refused({0.0, 1000.0, 3500.0}, {}, "past the mainline's end");
  refused({}, {"A1_west", "off_2", "A1_mall_park"}, "road/zone_start_edges[1] 'off_2' is not a mainline edge");
  refused({}, {"A1_harbour", "A1_mall", "A1_park"}, "zone 0 starts where the mainline does, at 'A1_west'");
  refused({0.0, 1000.0, 2000.0}, {"A1_west", "A1_mall", "A1_park"}, "both given");
  // The scenario's own check, before any network is read, names the same keys.
  ScenarioConfig bad = c;
  bad.road.zone_starts_m = {0.0, 1000.0, 1000.5};
  EXPECT_THROW_NAMING(validateScenarioConfig(bad), std::invalid_argument,
                      "road/zone_starts_m[2] = 1000.5 m must be at least 1 m after");
  bad.road.zone_starts_m.clear();
  bad.road.zone_start_edges = {"A1_west", "A1_mall", "A1_mall"};
  EXPECT_THROW_NAMING(validateScenarioConfig(bad), std::invalid_argument, "'A1_mall' starts zone 1 already");
  // A road of the naming convention: its zones are its clusters.
  ScenarioConfig generated;
  generated.scenario_dir = scenarioDir("tiny");
  generated.road.zone_starts_m = {0.0, 400.0, 1200.0};
  EXPECT_THROW_NAMING(validateScenarioConfig(generated), std::invalid_argument,
                      "road/zone_starts_m is only read with network_file");
}

// Hand-made topologies for the rule's corner cases (no netconvert needed).
NetTopology straightRoad(const std::vector<std::tuple<std::string, std::string, std::string, int>>& edges,
                         const std::vector<std::pair<std::string, std::string>>& links) {
  NetTopology net;
  for (const auto& [id, from, to, lanes] : edges) {
    net.edges.push_back({id, from, to, false, lanes, 500.0});
    for (int l = 0; l < lanes; ++l) net.lane_length_m[id + "_" + std::to_string(l)] = 500.0;
  }
  for (const auto& [from, to] : links) net.links.push_back({from, 0, to, 0, ""});
  return net;
}

TEST(OwnRoad, TwoOffRampsInOneZoneAreRefusedNamingBoth) {
  const NetTopology net = straightRoad(
      {{"a", "n0", "n1", 3}, {"b", "n1", "n2", 3}, {"c", "n2", "n3", 3}, {"x1", "n1", "r1", 1}, {"x2", "n2", "r2", 1}},
      {{"a", "b"}, {"b", "c"}, {"a", "x1"}, {"b", "x2"}});
  OwnRoadOptions o;
  o.clusters = 1;
  EXPECT_THROW_NAMING(discoverOwnRoad(net, o), std::invalid_argument, "zone 0 has two off-ramps ('x1' and 'x2')");
  o.clusters = 3;  // 500 m zones: one exit in each of zones 0 and 1
  const OwnRoad road = discoverOwnRoad(net, o);
  EXPECT_EQ(road.mainline, (std::vector<std::string>{"a", "b", "c"}));
  EXPECT_EQ(road.exit_from_edge.at(0), "a");
  EXPECT_EQ(road.exit_from_edge.at(1), "b");
}

TEST(OwnRoad, JunctionLanesOntoAnOffRampAreItsOwn) {
  NetTopology net = straightRoad({{"a", "n0", "n1", 3}, {"b", "n1", "n2", 3}, {"x", "n1", "r", 1}},
                                 {{"a", "b"}, {"a", "x"}});
  net.links[0].via = ":n1_1_0";   // a -> b, straight on
  net.links[1].via = ":n1_0_0";   // a -> x, onto the off-ramp, then a second internal lane
  net.links.push_back({":n1_0", 0, "x", 0, ":n1_2_0"});
  net.lane_length_m[":n1_1_0"] = 5.0;
  net.lane_length_m[":n1_0_0"] = 30.0;
  net.lane_length_m[":n1_2_0"] = 6.0;
  OwnRoadOptions o;
  o.clusters = 2;
  const OwnRoad road = discoverOwnRoad(net, o);
  EXPECT_EQ(road.onto_off_ramp, (std::map<std::string, std::string>{{":n1_0", "x"}, {":n1_2", "x"}}));
  const RoadLayout layout(road);
  EXPECT_EQ(layout.offRampEdges(), (std::map<std::string, int>{{"x", 0}, {":n1_0", 0}, {":n1_2", 0}}));
  // An internal edge the way to the ramp shares with the way straight on is not the ramp's.
  net.links[0].via = ":n1_2_0";
  EXPECT_EQ(discoverOwnRoad(net, o).onto_off_ramp, (std::map<std::string, std::string>{{":n1_0", "x"}}));
}

TEST(OwnRoad, AnAmbiguousMainlineAsksForTheEdgeList) {
  const NetTopology two_sources = straightRoad({{"a", "n0", "n2", 2}, {"b", "n1", "n2", 2}, {"c", "n2", "n3", 2}},
                                               {{"a", "c"}, {"b", "c"}});
  EXPECT_THROW_NAMING(discoverOwnRoad(two_sources, {}), std::invalid_argument,
                      "2 source edges have 2 lanes (a, b); list the mainline in mainline_edges");
  const NetTopology split = straightRoad({{"a", "n0", "n1", 2}, {"b", "n1", "n2", 2}, {"c", "n1", "n3", 2}},
                                         {{"a", "b"}, {"a", "c"}});
  EXPECT_THROW_NAMING(discoverOwnRoad(split, {}), std::invalid_argument, "after 'a' the road splits into b, c");
}

}  // namespace
}  // namespace palcas::sim
