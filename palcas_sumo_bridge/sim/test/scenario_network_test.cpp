// The networks generated from RoadSpecs: where their edges sit, how their lanes connect, and
// that the paper and tiny specs give the networks of the former hand-written sources
// (test/data/hand_written_{paper,tiny}).
#include <gtest/gtest.h>

#include "common/throws_naming.h"

#include <algorithm>
#include <filesystem>
#include <map>
#include <set>
#include <tuple>

#include "palcas_sim/road_layout.h"
#include "palcas_sim/scenario.h"
#include "scenario_test_util.h"

using palcas::sim::EdgeInfo;
using palcas::sim::LaneConnection;
using palcas::sim::RoadLayout;
using palcas::sim::RoadSpec;
using palcas::sim::test::freshDir;
using palcas::sim::test::handWrittenDir;
using palcas::sim::test::scenarioDir;
using palcas::sim::test::tinyRoad;

namespace {

std::map<std::string, EdgeInfo> byId(const std::vector<EdgeInfo>& edges) {
  std::map<std::string, EdgeInfo> out;
  for (const EdgeInfo& e : edges) out[e.id] = e;
  return out;
}

using Link = std::tuple<std::string, int, std::string, int>;

/// Every cluster of `road` sits where `spec` puts it: zone, ramps by the naming convention,
/// merge edge of L + 1 lanes, acceleration lane and exit at the spec's offsets.
void expectClustersOfSpec(const RoadLayout& road, const RoadSpec& spec) {
  ASSERT_EQ(road.clusters().size(), static_cast<std::size_t>(spec.clusters));
  EXPECT_EQ(road.numMainLanes(), spec.num_lanes);
  EXPECT_DOUBLE_EQ(road.mainlineLengthM(), spec.clusters * spec.cluster_length_m);
  for (int k = 0; k < spec.clusters; ++k) {
    const auto& c = road.clusters()[k];
    const double b = spec.cluster_length_m * k;
    EXPECT_DOUBLE_EQ(c.x_start_m, b);
    EXPECT_DOUBLE_EQ(c.x_end_m, b + spec.cluster_length_m);
    EXPECT_EQ(c.on_ramp_edge, "on_" + std::to_string(k));
    EXPECT_EQ(c.merge_edge, "main_" + std::to_string(k) + "_merge");
    EXPECT_EQ(road.edge(c.merge_edge).lane_count, spec.num_lanes + 1);  // + the acceleration lane
    EXPECT_NEAR(c.accel_lane_x_start_m, b + spec.merge_start_m, 0.01);
    EXPECT_NEAR(c.accel_lane_length_m, spec.acceleration_lane_m, 0.01);
    EXPECT_EQ(c.off_ramp_edge, "off_" + std::to_string(k));
    EXPECT_NEAR(c.exit_x_m, b + spec.exit_m, 0.01);
    EXPECT_NEAR(road.edge("on_" + std::to_string(k)).x_start_m, b, 0.01);
    EXPECT_NEAR(road.edge("off_" + std::to_string(k)).x_end_m, b + spec.cluster_length_m, 0.01);
    EXPECT_LT(c.accel_lane_x_start_m + c.accel_lane_length_m, c.exit_x_m);  // merge before exit
  }
}

std::set<Link> links(const std::vector<LaneConnection>& connections) {
  std::set<Link> out;
  for (const LaneConnection& c : connections) out.insert({c.from_edge, c.from_lane, c.to_edge, c.to_lane});
  return out;
}

/// The connections a cluster must have, by the README's layout, for `lanes` through lanes.
std::set<Link> expectedClusterLinks(int k, int lanes, bool last) {
  const std::string p = "main_" + std::to_string(k) + "_";
  std::set<Link> out{{"on_" + std::to_string(k), 0, p + "merge", 0},   // ramp -> accel lane only
                     {p + "mid", 0, "off_" + std::to_string(k), 0}};  // exit from lane 1
  for (int l = 0; l < lanes; ++l) {
    out.insert({p + "up", l, p + "merge", l + 1});  // merge edge: SUMO lane 0 is the accel lane
    out.insert({p + "merge", l + 1, p + "mid", l});  // accel lane (0) ends: no link from it
    out.insert({p + "mid", l, p + "down", l});
    if (!last) out.insert({p + "down", l, "main_" + std::to_string(k + 1) + "_up", l});
  }
  return out;
}

struct ExpectedEdge {
  std::string id;
  double x_start_m, x_end_m;
  int lanes;
};

void expectEdges(const std::map<std::string, EdgeInfo>& edges, const std::vector<ExpectedEdge>& expected) {
  EXPECT_EQ(edges.size(), expected.size());
  for (const ExpectedEdge& e : expected) {
    ASSERT_EQ(edges.count(e.id), 1u) << e.id;
    const EdgeInfo& got = edges.at(e.id);
    EXPECT_NEAR(got.x_start_m, e.x_start_m, 0.01) << e.id;  // no junction cut-back
    EXPECT_NEAR(got.x_end_m, e.x_end_m, 0.01) << e.id;
    EXPECT_EQ(got.lane_count, e.lanes) << e.id;
  }
}

/// The same network: the same non-internal edges (ids, lane counts, lane 0's x range within
/// 0.01 m) and the same lane connections.
void expectSameNetwork(const std::string& got_net, const std::string& want_net) {
  const auto got = byId(palcas::sim::readNetEdges(got_net));
  const auto want = byId(palcas::sim::readNetEdges(want_net));
  EXPECT_EQ(got.size(), want.size());
  for (const auto& [id, w] : want) {
    ASSERT_EQ(got.count(id), 1u) << id;
    EXPECT_EQ(got.at(id).lane_count, w.lane_count) << id;
    EXPECT_NEAR(got.at(id).x_start_m, w.x_start_m, 0.01) << id;
    EXPECT_NEAR(got.at(id).x_end_m, w.x_end_m, 0.01) << id;
  }
  EXPECT_EQ(links(palcas::sim::readNetConnections(got_net)),
            links(palcas::sim::readNetConnections(want_net)));
}

}  // namespace

TEST(ScenarioNetwork, PaperSpecGivesTheHandWrittenPaperNetwork) {
  expectSameNetwork(palcas::sim::generateNetwork(RoadSpec{}, freshDir("same_paper_gen")),
                    palcas::sim::generateNetwork(handWrittenDir("paper"), freshDir("same_paper_hw")));
}

TEST(ScenarioNetwork, TinySpecGivesTheHandWrittenTinyNetwork) {
  expectSameNetwork(palcas::sim::generateNetwork(tinyRoad(), freshDir("same_tiny_gen")),
                    palcas::sim::generateNetwork(handWrittenDir("tiny"), freshDir("same_tiny_hw")));
}

TEST(ScenarioNetwork, SourcesAreWrittenBesideTheNetwork) {
  const std::string out = freshDir("net_sources");
  EXPECT_EQ(palcas::sim::generateNetwork(tinyRoad(), out), out + "/network.net.xml");
  for (const char* f : {"network.nod.xml", "network.edg.xml", "network.con.xml"})
    EXPECT_TRUE(std::filesystem::is_regular_file(out + "/sources/" + f)) << f;
  RoadSpec bad = tinyRoad();
  bad.exit_m = 300.0;  // at the cluster's end: no room for main_k_down
  const std::string never = freshDir("net_sources_bad") + "/never";
  EXPECT_THROW(palcas::sim::generateNetwork(bad, never), std::invalid_argument);
  EXPECT_FALSE(std::filesystem::exists(never));
}

TEST(ScenarioNetwork, FourClustersOfFourLanesFromASpec) {
  RoadSpec spec;
  spec.clusters = 4;
  spec.num_lanes = 4;
  spec.cluster_length_m = 500.0;
  spec.warmup_length_m = 50.0;
  spec.merge_start_m = 80.0;
  spec.acceleration_lane_m = 150.0;
  spec.exit_m = 400.0;
  const std::string net = palcas::sim::generateNetwork(spec, freshDir("net_four"));
  const auto edges = palcas::sim::readNetEdges(net);
  EXPECT_EQ(edges.size(), 1u + 4u * 6u);  // warm-up + (up, merge, mid, down, on, off) per cluster
  const RoadLayout road(edges, 4, 500.0);
  expectClustersOfSpec(road, spec);
  EXPECT_NEAR(road.edge("main_0_warmup").x_end_m, 50.0, 0.01);
  std::set<Link> expected;
  for (int l = 0; l < 4; ++l) expected.insert({"main_0_warmup", l, "main_0_up", l});
  for (int k = 0; k < 4; ++k) {
    const std::set<Link> cluster = expectedClusterLinks(k, 4, k == 3);
    expected.insert(cluster.begin(), cluster.end());
  }
  EXPECT_EQ(links(palcas::sim::readNetConnections(net)), expected);
}

TEST(ScenarioNetwork, PaperEdgesSitWhereTheSpecPutsThem) {
  const std::string net = palcas::sim::generateNetwork(RoadSpec{}, freshDir("net_paper"));
  // Cluster k spans [800k, 800k + 800): up to 800k+150, merge to 800k+400, exit at 800k+700.
  expectEdges(byId(palcas::sim::readNetEdges(net)),
              {{"main_0_warmup", 0, 100, 5},   {"main_0_up", 100, 150, 5},
               {"main_0_merge", 150, 400, 6},  {"main_0_mid", 400, 700, 5},
               {"main_0_down", 700, 800, 5},   {"on_0", 0, 150, 1},
               {"off_0", 700, 800, 1},         {"main_1_up", 800, 950, 5},
               {"main_1_merge", 950, 1200, 6}, {"main_1_mid", 1200, 1500, 5},
               {"main_1_down", 1500, 1600, 5}, {"on_1", 800, 950, 1},
               {"off_1", 1500, 1600, 1},       {"main_2_up", 1600, 1750, 5},
               {"main_2_merge", 1750, 2000, 6}, {"main_2_mid", 2000, 2300, 5},
               {"main_2_down", 2300, 2400, 5}, {"on_2", 1600, 1750, 1},
               {"off_2", 2300, 2400, 1}});
}

TEST(ScenarioNetwork, PaperRoadLayoutHasThreeClustersWithRampsAndExits) {
  const std::string net = palcas::sim::generateNetwork(RoadSpec{}, freshDir("layout_paper"));
  const RoadLayout road(palcas::sim::readNetEdges(net), 5, 800.0);
  expectClustersOfSpec(road, RoadSpec{});
  // The merge edge's SUMO lane 0 is the acceleration lane (paper lane 0), lane 1 the exit lane.
  EXPECT_EQ(road.paperLane("main_1_merge", 0), 0);
  EXPECT_EQ(road.paperLane("main_1_mid", 0), 1);
}

TEST(ScenarioNetwork, PaperLanesConnectAsTheReadmeSays) {
  const std::string net = palcas::sim::generateNetwork(RoadSpec{}, freshDir("links_paper"));
  std::set<Link> expected;
  for (int l = 0; l < 5; ++l) expected.insert({"main_0_warmup", l, "main_0_up", l});
  for (int k = 0; k < 3; ++k) {
    const std::set<Link> cluster = expectedClusterLinks(k, 5, k == 2);
    expected.insert(cluster.begin(), cluster.end());
  }
  // 5 + 2 x (2 + 4 x 5) + (2 + 3 x 5) = 5 + 44 + 17 = 66 links.
  EXPECT_EQ(expected.size(), 66u);
  EXPECT_EQ(links(palcas::sim::readNetConnections(net)), expected);
}

TEST(ScenarioNetwork, TinyEdgesLayoutAndLinks) {
  const std::string net = palcas::sim::generateNetwork(tinyRoad(), freshDir("net_tiny"));
  const auto edges = palcas::sim::readNetEdges(net);
  // Cluster k spans [300k, 300k + 300): up to +60, merge to +160, exit at +240.
  expectEdges(byId(edges), {{"main_0_warmup", 0, 40, 3},   {"main_0_up", 40, 60, 3},
                            {"main_0_merge", 60, 160, 4},  {"main_0_mid", 160, 240, 3},
                            {"main_0_down", 240, 300, 3},  {"on_0", 0, 60, 1},
                            {"off_0", 240, 300, 1},        {"main_1_up", 300, 360, 3},
                            {"main_1_merge", 360, 460, 4}, {"main_1_mid", 460, 540, 3},
                            {"main_1_down", 540, 600, 3},  {"on_1", 300, 360, 1},
                            {"off_1", 540, 600, 1}});
  const RoadLayout road(edges, 3, 300.0);
  EXPECT_DOUBLE_EQ(road.mainlineLengthM(), 600.0);  // 2 clusters x 300 m
  ASSERT_EQ(road.clusters().size(), 2u);
  EXPECT_NEAR(road.clusters()[1].accel_lane_x_start_m, 360.0, 0.01);  // 300 + 60
  EXPECT_NEAR(road.clusters()[1].accel_lane_length_m, 100.0, 0.01);   // 160 - 60
  EXPECT_NEAR(road.clusters()[1].exit_x_m, 540.0, 0.01);              // 300 + 240
  std::set<Link> expected;
  for (int l = 0; l < 3; ++l) expected.insert({"main_0_warmup", l, "main_0_up", l});
  for (int k = 0; k < 2; ++k) {
    const std::set<Link> cluster = expectedClusterLinks(k, 3, k == 1);
    expected.insert(cluster.begin(), cluster.end());
  }
  EXPECT_EQ(expected.size(), 28u);  // 3 + (2 + 4 x 3) + (2 + 3 x 3) = 3 + 14 + 11
  EXPECT_EQ(links(palcas::sim::readNetConnections(net)), expected);
}

TEST(ScenarioNetwork, MissingSourcesAreRejectedByName) {
  const std::string empty = freshDir("empty_sources");
  palcas_test::expectThrowNaming<std::invalid_argument>(
      [&] { palcas::sim::generateNetwork(empty, freshDir("out_empty")); }, "network.nod.xml");
}

TEST(ScenarioNetwork, NetconvertFailureCarriesItsOutput) {
  // A copy of the hand-written tiny sources whose edge names a node that does not exist.
  const std::string broken = freshDir("broken_sources");
  for (const char* f : {"network.nod.xml", "network.edg.xml", "network.con.xml"})
    std::filesystem::copy_file(handWrittenDir("tiny") + "/" + f, broken + "/" + f);
  std::string edges = palcas::sim::test::slurp(broken + "/network.edg.xml");
  edges.replace(edges.find("from=\"n_start\""), 14, "from=\"n_nowhere\"");
  std::ofstream(broken + "/network.edg.xml") << edges;
  const auto generate = [&] { palcas::sim::generateNetwork(broken, freshDir("out_broken")); };
  palcas_test::expectThrowNaming<std::runtime_error>(generate, "netconvert failed");
  palcas_test::expectThrowNaming<std::runtime_error>(generate, "n_nowhere");  // netconvert's own
}

TEST(ScenarioNetwork, MissingNetconvertIsAClearError) {
  EXPECT_THROW(palcas::sim::generateNetwork(handWrittenDir("tiny"), freshDir("out_nobin"),
                                            "/nonexistent/netconvert"),
               std::runtime_error);
}

TEST(ScenarioNetwork, ReadingSomethingThatIsNotANetworkFails) {
  EXPECT_THROW(palcas::sim::readNetEdges("/nonexistent/net.net.xml"), std::runtime_error);
  palcas_test::expectThrowNaming<std::runtime_error>(
      [&] { palcas::sim::readNetEdges(handWrittenDir("paper") + "/network.nod.xml"); },
      "not a SUMO network");
  EXPECT_THROW(palcas::sim::readNetConnections(scenarioDir("paper") + "/vtypes.xml"),
               std::runtime_error);
}
