// The demand writer: vehicle-type mix, routes, flows, .sumocfg, and bad configurations.
#include <gtest/gtest.h>

#include "common/throws_naming.h"

#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <regex>

#include "palcas_sim/scenario.h"
#include "scenario_test_util.h"

using palcas::sim::EdgeInfo;
using palcas::sim::ScenarioConfig;
using palcas::sim::test::freshDir;
using palcas::sim::test::handWrittenDir;
using palcas::sim::test::scenarioDir;
using palcas::sim::test::slurp;

namespace {

/// The paper road generated from the default RoadSpec, vtypes.xml from config/scenarios/paper.
ScenarioConfig paperConfig(double pr) {
  ScenarioConfig c;
  c.scenario_dir = scenarioDir("paper");
  c.penetration_rate = pr;
  c.cav_speed.p_fast = 0.75;  // distinct p_fast values so a swap would show
  c.hdv_speed.p_fast = 0.4;
  return c;
}

/// attribute `key` of the first tag whose id is `id`.
std::string attributeOf(const std::string& xml, const std::string& id, const std::string& key) {
  const std::regex tag("<[a-zA-Z]+ id=\"" + id + "\"[^>]*>");
  std::smatch m;
  if (!std::regex_search(xml, m, tag)) return "<no tag " + id + ">";
  const std::regex attr(" " + key + "=\"([^\"]*)\"");
  std::smatch a;
  const std::string t = m.str();
  return std::regex_search(t, a, attr) ? a[1].str() : "<no " + key + ">";
}

/// route id -> vehsPerHour of every flow in a routes file.
std::map<std::string, double> flows(const std::string& xml) {
  std::map<std::string, double> out;
  const std::regex flow("<flow [^>]*route=\"([^\"]+)\"[^>]*vehsPerHour=\"([^\"]+)\"");
  for (auto it = std::sregex_iterator(xml.begin(), xml.end(), flow); it != std::sregex_iterator(); ++it)
    out[(*it)[1].str()] = std::stod((*it)[2].str());
  return out;
}

double sumWithPrefix(const std::map<std::string, double>& f, const std::string& prefix) {
  double sum = 0.0;
  for (const auto& [route, vph] : f)
    if (route.rfind(prefix, 0) == 0) sum += vph;
  return sum;
}

/// A hand-made two-cluster, 5-lane road (no netconvert), as road_layout_test's.
std::vector<EdgeInfo> twoClusterEdges() {
  std::vector<EdgeInfo> e{{"main_0_warmup", {}, -1, 0, 100, 5, false}};
  for (int k = 0; k < 2; ++k) {
    const double x = 800.0 * k;
    const std::string p = "main_" + std::to_string(k) + "_";
    e.push_back({p + "up", {}, -1, k == 0 ? 100 : x, x + 150, 5, false});
    e.push_back({p + "merge", {}, -1, x + 150, x + 400, 6, false});
    e.push_back({p + "mid", {}, -1, x + 400, x + 700, 5, false});
    e.push_back({p + "down", {}, -1, x + 700, x + 800, 5, false});
    e.push_back({"on_" + std::to_string(k), {}, -1, x, x + 150, 1, false});
    e.push_back({"off_" + std::to_string(k), {}, -1, x + 700, x + 800, 1, false});
  }
  return e;
}

ScenarioConfig twoClusterConfig() {
  ScenarioConfig c;
  c.scenario_dir = "unused-by-buildRoutes";
  c.road.clusters = 2;
  c.route_shares = palcas::sim::defaultRouteShares(2);
  return c;
}

template <typename F>
void expectInvalid(F f, const std::string& needle) {
  palcas_test::expectThrowNaming<std::invalid_argument>(f, needle);
}

}  // namespace

TEST(ScenarioDemand, TypeProbabilitiesFollowPenetrationRateAndPFast) {
  // cav_fast = PR 0.75, cav_slow = PR 0.25, hdv_fast = (1-PR) 0.4, hdv_slow = (1-PR) 0.6
  struct Case { double pr, cav_fast, cav_slow, hdv_fast, hdv_slow; };
  for (const Case& k : {Case{0.0, 0.0, 0.0, 0.4, 0.6},         // 1 x 0.4, 1 x 0.6
                        Case{0.6, 0.45, 0.15, 0.16, 0.24},     // .6x.75, .6x.25, .4x.4, .4x.6
                        Case{1.0, 0.75, 0.25, 0.0, 0.0}}) {
    const std::string out = freshDir("types_" + std::to_string(static_cast<int>(k.pr * 10)));
    const auto files = palcas::sim::writeScenario(paperConfig(k.pr), out);
    const std::string xml = slurp(files.routes_file);
    EXPECT_NEAR(std::stod(attributeOf(xml, "cav_fast", "probability")), k.cav_fast, 1e-9);
    EXPECT_NEAR(std::stod(attributeOf(xml, "cav_slow", "probability")), k.cav_slow, 1e-9);
    EXPECT_NEAR(std::stod(attributeOf(xml, "hdv_fast", "probability")), k.hdv_fast, 1e-9);
    EXPECT_NEAR(std::stod(attributeOf(xml, "hdv_slow", "probability")), k.hdv_slow, 1e-9);
  }
}

TEST(ScenarioDemand, VehicleTypesCarryTemplateAndTwoPointSpeeds) {
  const auto files = palcas::sim::writeScenario(paperConfig(0.6), freshDir("vtypes"));
  const std::string xml = slurp(files.routes_file);
  EXPECT_NE(xml.find("<vTypeDistribution id=\"mixed\">"), std::string::npos);
  EXPECT_EQ(attributeOf(xml, "cav_fast", "maxSpeed"), "33.528");
  EXPECT_EQ(attributeOf(xml, "cav_slow", "maxSpeed"), "29.0576");
  EXPECT_EQ(attributeOf(xml, "hdv_fast", "maxSpeed"), "33.528");
  EXPECT_EQ(attributeOf(xml, "cav_fast", "sigma"), "0.0");   // config/scenarios/paper/vtypes.xml
  EXPECT_EQ(attributeOf(xml, "hdv_slow", "sigma"), "0.5");
  EXPECT_EQ(attributeOf(xml, "hdv_slow", "laneChangeModel"), "SL2015");
  EXPECT_TRUE(palcas::sim::isCavType("cav_slow"));
  EXPECT_FALSE(palcas::sim::isCavType("hdv_fast"));
}

TEST(ScenarioDemand, FlowsSplitTheConfiguredTotalsByRouteShare) {
  const auto files = palcas::sim::writeScenario(paperConfig(0.6), freshDir("flows"));
  const auto f = flows(slurp(files.routes_file));
  EXPECT_NEAR(sumWithPrefix(f, "r_main_"), 16000.0, 1e-6);  // 3200 veh/h/lane x 5 lanes
  EXPECT_NEAR(sumWithPrefix(f, "r_on0_"), 600.0, 1e-6);     // 600 veh/h/lane x 1 lane
  EXPECT_NEAR(sumWithPrefix(f, "r_on1_"), 600.0, 1e-6);
  EXPECT_NEAR(sumWithPrefix(f, "r_on2_"), 600.0, 1e-6);
  EXPECT_NEAR(f.at("r_main_end"), 8800.0, 1e-6);   // 16000 x 0.55
  EXPECT_NEAR(f.at("r_main_off1"), 2400.0, 1e-6);  // 16000 x 0.45 / 3 (paper Route One)
  EXPECT_NEAR(f.at("r_on0_off1"), 180.0, 1e-6);    // 600 x 0.6 / 2 (paper Route Four)
  EXPECT_NEAR(f.at("r_on1_off2"), 360.0, 1e-6);    // 600 x 0.6 / 1
  EXPECT_NEAR(f.at("r_on2_end"), 600.0, 1e-6);     // last ramp: all to the end
  EXPECT_EQ(f.size(), 10u);  // main: end + 3 exits; on0: 3; on1: 2; on2: 1
}

TEST(ScenarioDemand, RoutesFollowTheMainlineFromTheirSource) {
  const auto files = palcas::sim::writeScenario(paperConfig(0.6), freshDir("routes"));
  const std::string xml = slurp(files.routes_file);
  EXPECT_EQ(attributeOf(xml, "r_on0_off1", "edges"),
            "on_0 main_0_merge main_0_mid main_0_down main_1_up main_1_merge main_1_mid off_1");
  EXPECT_EQ(attributeOf(xml, "r_main_off0", "edges"),
            "main_0_warmup main_0_up main_0_merge main_0_mid off_0");
  EXPECT_EQ(attributeOf(xml, "f_main_end", "departPos"), "random_free");
  EXPECT_EQ(attributeOf(xml, "f_on1_end", "departPos"), "base");
}

TEST(ScenarioDemand, SumocfgCarriesSeedAndSimulationOptions) {
  ScenarioConfig c = paperConfig(0.6);
  c.seed = 1234;
  c.duration_s = 900;
  c.max_depart_delay_s = 7.5;
  c.time_to_teleport_s = -5;  // any negative: never teleport, written as SUMO's -1
  const auto files = palcas::sim::writeScenario(c, freshDir("cfg"));
  const std::string cfg = slurp(files.sumocfg_file);
  for (const char* line : {"<seed value=\"1234\"/>", "<end value=\"900\"/>",
                           "<step-length value=\"0.1\"/>", "<lateral-resolution value=\"3.2\"/>",
                           "<collision.action value=\"remove\"/>",
                           "<collision.mingap-factor value=\"0\"/>",
                           "<collision.check-junctions value=\"true\"/>",
                           "<max-depart-delay value=\"7.5\"/>", "<time-to-teleport value=\"-1\"/>",
                           "<net-file value=\"network.net.xml\"/>",
                           "<route-files value=\"routes.rou.xml\"/>"})
    EXPECT_NE(cfg.find(line), std::string::npos) << line;
  EXPECT_EQ(cfg.find("output"), std::string::npos);  // no output files by default
  EXPECT_TRUE(std::filesystem::is_regular_file(files.net_file));
}

TEST(ScenarioDemand, DefaultRouteSharesSumToOnePerSource) {
  const auto s = palcas::sim::defaultRouteShares(3);
  EXPECT_DOUBLE_EQ(s.at("main").at("end"), 0.55);
  EXPECT_DOUBLE_EQ(s.at("main").at("off2"), 0.15);  // 0.45 / 3
  EXPECT_DOUBLE_EQ(s.at("on0").at("off2"), 0.3);    // 0.6 / 2
  EXPECT_DOUBLE_EQ(s.at("on2").at("end"), 1.0);
  EXPECT_EQ(s.at("on1").count("off1"), 0u);  // an on-ramp reaches only exits downstream
  EXPECT_THROW(palcas::sim::defaultRouteShares(0), std::invalid_argument);
}

TEST(ScenarioDemand, RejectsBadScalarsBeforeWritingAnything) {
  const std::string out = freshDir("bad_scalars") + "/never";
  auto bad = [&](auto mutate, const std::string& needle) {
    ScenarioConfig c = paperConfig(0.6);
    mutate(c);
    expectInvalid([&] { palcas::sim::writeScenario(c, out); }, needle);
    EXPECT_FALSE(std::filesystem::exists(out)) << needle;
  };
  bad([](ScenarioConfig& c) { c.penetration_rate = -0.1; }, "penetration_rate");
  bad([](ScenarioConfig& c) { c.penetration_rate = 1.1; }, "penetration_rate");
  bad([](ScenarioConfig& c) { c.penetration_rate = std::nan(""); }, "penetration_rate");
  bad([](ScenarioConfig& c) { c.mainline_flow_vphpl = -1; }, "mainline_flow_vphpl");
  bad([](ScenarioConfig& c) { c.onramp_flow_vphpl = -600; }, "onramp_flow_vphpl");
  bad([](ScenarioConfig& c) { c.duration_s = 0; }, "duration_s");
  bad([](ScenarioConfig& c) { c.hdv_speed.p_fast = 2; }, "hdv_speed.p_fast");
  bad([](ScenarioConfig& c) { c.cav_speed.slow_mps = 40; }, "cav_speed");
  bad([](ScenarioConfig& c) { c.mainline_insertion.depart_pos = "anywhere"; }, "depart_pos");
  bad([](ScenarioConfig& c) { c.max_depart_delay_s = std::numeric_limits<double>::infinity(); },
      "max_depart_delay_s");
  bad([](ScenarioConfig& c) { c.scenario_dir = ""; }, "scenario_dir");
  bad([](ScenarioConfig& c) { c.road.clusters = 0; }, "road/clusters");
  bad([](ScenarioConfig& c) { c.road.exit_m = 900; }, "road/exit_m");
  bad([](ScenarioConfig& c) { c.road.lane_width_m = 0; }, "road/lane_width_m");
  bad([](ScenarioConfig& c) { c.scenario_dir = "/nonexistent/scenario"; }, "/nonexistent/scenario");
}

TEST(ScenarioDemand, RejectsBadRouteShares) {
  const auto edges = twoClusterEdges();
  auto bad = [&](auto mutate, const std::string& needle) {
    ScenarioConfig c = twoClusterConfig();
    mutate(c);
    expectInvalid([&] { palcas::sim::buildRoutes(c, edges); }, needle);
  };
  bad([](ScenarioConfig& c) { c.route_shares["main"]["end"] = 0.5; }, "sums to");  // 0.5+0.225x2
  bad([](ScenarioConfig& c) { c.route_shares["main"]["off0"] = -0.1; }, "off0");
  bad([](ScenarioConfig& c) { c.route_shares["on1"] = {{"end", 0.5}, {"off0", 0.5}}; }, "off0");
  bad([](ScenarioConfig& c) { c.route_shares["on0"] = {{"end", 0.5}, {"off0", 0.5}}; }, "off0");
  bad([](ScenarioConfig& c) { c.route_shares["main"]["off9"] = 0.0; }, "off9");
  bad([](ScenarioConfig& c) { c.route_shares.erase("on1"); }, "on1");
  bad([](ScenarioConfig& c) { c.route_shares["on7"] = {{"end", 1.0}}; }, "on7");
  // A share problem found by writeScenario: the paper road has 3 clusters, defaults for 2.
  ScenarioConfig c = paperConfig(0.6);
  c.route_shares = palcas::sim::defaultRouteShares(2);
  const std::string out = freshDir("bad_shares");
  expectInvalid([&] { palcas::sim::writeScenario(c, out); }, "on2");
  EXPECT_FALSE(std::filesystem::exists(out + "/scenario.sumocfg"));
}

TEST(ScenarioDemand, BuildRoutesOnAHandMadeRoad) {
  ScenarioConfig c = twoClusterConfig();
  c.mainline_flow_vphpl = 1000;
  const auto routes = palcas::sim::buildRoutes(c, twoClusterEdges());
  // main: end, off0, off1; on0: end, off1; on1: end
  ASSERT_EQ(routes.size(), 6u);
  EXPECT_EQ(routes[0].id, "r_main_end");
  EXPECT_NEAR(routes[0].vehs_per_hour, 2750.0, 1e-9);  // 1000 x 5 lanes x 0.55
  EXPECT_EQ(routes[1].id, "r_main_off0");
  EXPECT_NEAR(routes[1].vehs_per_hour, 1125.0, 1e-9);  // 5000 x 0.45 / 2
  EXPECT_EQ(routes[1].edges, (std::vector<std::string>{"main_0_warmup", "main_0_up",
                                                       "main_0_merge", "main_0_mid", "off_0"}));
  EXPECT_EQ(routes[4].id, "r_on0_off1");
  EXPECT_TRUE(routes[4].from_ramp);
  EXPECT_NEAR(routes[4].vehs_per_hour, 360.0, 1e-9);  // 600 x 0.6
  // A gap in the mainline is an error naming the edges on both sides.
  auto gap = twoClusterEdges();
  gap[3].x_end_m = 690;  // main_0_mid now ends at 690, main_0_down starts at 700
  expectInvalid([&] { palcas::sim::buildRoutes(c, gap); }, "main_0_mid");
  // The network must be the configured road: cluster and lane counts are compared.
  c.road.clusters = 3;
  expectInvalid([&] { palcas::sim::buildRoutes(c, twoClusterEdges()); }, "road/clusters is 3");
  c.road.clusters = 2;
  c.road.num_lanes = 4;
  expectInvalid([&] { palcas::sim::buildRoutes(c, twoClusterEdges()); }, "road/num_lanes is 4");
}

TEST(ScenarioDemand, EmptyRouteSharesMeanTheDefaultForTheRoad) {
  ScenarioConfig c = paperConfig(0.6);
  ASSERT_TRUE(c.route_shares.empty());  // the default
  c.road.clusters = 4;
  c.road.num_lanes = 4;
  c.mainline_flow_vphpl = 1000;
  const auto files = palcas::sim::writeScenario(c, freshDir("default_shares"));
  const auto f = flows(slurp(files.routes_file));
  // main: end + 4 exits; on0: end + off1..3; on1: 3; on2: 2; on3: end only.
  EXPECT_EQ(f.size(), 15u);
  EXPECT_NEAR(f.at("r_main_end"), 2200.0, 1e-6);    // 1000 x 4 lanes x 0.55
  EXPECT_NEAR(f.at("r_main_off3"), 450.0, 1e-6);    // 4000 x 0.45 / 4
  EXPECT_NEAR(f.at("r_on0_off3"), 120.0, 1e-6);     // 600 x 0.6 / 3
  EXPECT_NEAR(f.at("r_on3_end"), 600.0, 1e-6);      // the last ramp: all to the end
  // buildRoutes applies the same default.
  const auto routes = palcas::sim::buildRoutes(c, palcas::sim::readNetEdges(files.net_file));
  ASSERT_EQ(routes.size(), 15u);
  EXPECT_EQ(routes.back().id, "r_on3_end");
  EXPECT_EQ(routes.back().edges, (std::vector<std::string>{"on_3", "main_3_merge", "main_3_mid",
                                                          "main_3_down"}));
}

TEST(ScenarioDemand, HandWrittenNetworkWhenGenerationIsOff) {
  // A folder with the hand-written tiny sources and the tiny vehicle types.
  const std::string dir = freshDir("hand_written");
  for (const char* f : {"network.nod.xml", "network.edg.xml", "network.con.xml"})
    std::filesystem::copy_file(handWrittenDir("tiny") + "/" + f, dir + "/" + f);
  std::filesystem::copy_file(scenarioDir("tiny") + "/vtypes.xml", dir + "/vtypes.xml");
  ScenarioConfig c;
  c.scenario_dir = dir;
  c.generate_network = false;
  c.road.clusters = 2;  // only the counts and the zone length describe a hand-written road ...
  c.road.num_lanes = 3;
  c.road.cluster_length_m = 300;
  c.road.exit_m = 1e9;  // ... the rest is not read
  const auto files = palcas::sim::writeScenario(c, dir + "/out");
  EXPECT_FALSE(std::filesystem::exists(dir + "/out/sources"));
  const auto f = flows(slurp(files.routes_file));
  EXPECT_NEAR(f.at("r_on1_end"), 600.0, 1e-6);  // defaultRouteShares(2)
  EXPECT_EQ(f.size(), 6u);
  c.road.clusters = 3;  // not this network
  expectInvalid([&] { palcas::sim::writeScenario(c, dir + "/out3"); }, "road/clusters");
  c.road.clusters = 2;
  c.road.num_lanes = 0;
  expectInvalid([&] { palcas::sim::writeScenario(c, dir + "/out0"); }, "road/num_lanes");
  c.road.num_lanes = 3;
  c.scenario_dir = scenarioDir("tiny") + "/no_such_folder";
  expectInvalid([&] { palcas::sim::writeScenario(c, dir + "/out_missing"); }, "no_such_folder");
}

TEST(ScenarioDemand, RejectsVTypeTemplateThatSetsMaxSpeed) {
  const std::string dir = freshDir("bad_vtypes");
  std::filesystem::copy_file(scenarioDir("tiny") + "/vtypes.xml", dir + "/vtypes.xml");
  std::string vtypes = slurp(dir + "/vtypes.xml");
  vtypes.replace(vtypes.find("<vType id=\"cav\""), 15, "<vType id=\"cav\" maxSpeed=\"50\"");
  std::ofstream(dir + "/vtypes.xml") << vtypes;
  ScenarioConfig c;
  c.scenario_dir = dir;
  c.road = palcas::sim::test::tinyRoad();
  expectInvalid([&] { palcas::sim::writeScenario(c, dir + "/out"); }, "maxSpeed");
  std::filesystem::remove(dir + "/vtypes.xml");
  expectInvalid([&] { palcas::sim::writeScenario(c, dir + "/out"); }, "vtypes.xml");
}
