// RoadSpec checks, zone boundaries and writing the sources (no netconvert here; the networks
// they make are checked in scenario_network_test).
#include "palcas_sim/road_spec.h"

#include <gtest/gtest.h>

#include "common/throws_naming.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <regex>

#include "scenario_test_util.h"

using palcas::sim::RoadSpec;
using palcas::sim::test::freshDir;
using palcas::sim::test::slurp;

namespace {

/// The spec with one field changed must be rejected by a message naming "road/<field>" and the
/// value as the message writes it; writeNetworkSources must not create its folder.
void expectRejected(const std::function<void(RoadSpec&)>& mutate, const std::string& field,
                    const std::string& value) {
  RoadSpec road;
  mutate(road);
  const std::string needle = "road/" + field + " = " + value;
  palcas_test::expectThrowNaming<std::invalid_argument>(
      [&] { palcas::sim::validateRoadSpec(road); }, needle);
  const std::string dir = freshDir("bad_road") + "/never";
  EXPECT_THROW(palcas::sim::writeNetworkSources(road, dir), std::invalid_argument) << needle;
  EXPECT_FALSE(std::filesystem::exists(dir)) << needle;
}

/// The XML without comments, whitespace runs collapsed to one space.
std::string withoutComments(const std::string& xml) {
  const std::string bare = std::regex_replace(xml, std::regex("<!--[\\s\\S]*?-->"), " ");
  return std::regex_replace(bare, std::regex("\\s+"), " ");
}

constexpr double NaN = std::numeric_limits<double>::quiet_NaN();
constexpr double INF = std::numeric_limits<double>::infinity();

}  // namespace

TEST(RoadSpec, PaperAndTinySpecsAreValid) {
  EXPECT_NO_THROW(palcas::sim::validateRoadSpec(RoadSpec{}));
  EXPECT_NO_THROW(palcas::sim::validateRoadSpec(palcas::sim::test::tinyRoad()));
}

TEST(RoadSpec, RejectsEachBadFieldByName) {
  expectRejected([](RoadSpec& r) { r.clusters = 0; }, "clusters", "0");
  expectRejected([](RoadSpec& r) { r.clusters = 101; }, "clusters", "101");
  expectRejected([](RoadSpec& r) { r.num_lanes = 0; }, "num_lanes", "0");
  expectRejected([](RoadSpec& r) { r.num_lanes = 11; }, "num_lanes", "11");
  expectRejected([](RoadSpec& r) { r.cluster_length_m = 0; }, "cluster_length_m", "0");
  expectRejected([](RoadSpec& r) { r.cluster_length_m = NaN; }, "cluster_length_m", "nan");
  expectRejected([](RoadSpec& r) { r.cluster_length_m = 2e5; }, "cluster_length_m", "200000");
  expectRejected([](RoadSpec& r) { r.warmup_length_m = 0; }, "warmup_length_m", "0");
  expectRejected([](RoadSpec& r) { r.warmup_length_m = -5; }, "warmup_length_m", "-5");
  expectRejected([](RoadSpec& r) { r.warmup_length_m = 150; }, "merge_start_m", "150");  // = merge
  expectRejected([](RoadSpec& r) { r.merge_start_m = 99.5; }, "merge_start_m", "99.5");  // < warmup
  expectRejected([](RoadSpec& r) { r.merge_start_m = INF; }, "merge_start_m", "inf");
  expectRejected([](RoadSpec& r) { r.acceleration_lane_m = 0; }, "acceleration_lane_m", "0");
  expectRejected([](RoadSpec& r) { r.acceleration_lane_m = 550; }, "exit_m", "700");  // 150+550
  expectRejected([](RoadSpec& r) { r.exit_m = 400; }, "exit_m", "400");  // = merge end
  expectRejected([](RoadSpec& r) { r.exit_m = 800; }, "exit_m", "800");  // = cluster length
  expectRejected([](RoadSpec& r) { r.exit_m = NaN; }, "exit_m", "nan");
  expectRejected([](RoadSpec& r) { r.lane_width_m = 0; }, "lane_width_m", "0");
  expectRejected([](RoadSpec& r) { r.lane_width_m = -3.2; }, "lane_width_m", "-3.2");
  expectRejected([](RoadSpec& r) { r.lane_width_m = 12; }, "lane_width_m", "12");
  expectRejected([](RoadSpec& r) { r.speed_limit_mps = 0; }, "speed_limit_mps", "0");
  expectRejected([](RoadSpec& r) { r.speed_limit_mps = -INF; }, "speed_limit_mps", "-inf");
  expectRejected([](RoadSpec& r) { r.ramp_speed_limit_mps = -1; }, "ramp_speed_limit_mps", "-1");
  expectRejected([](RoadSpec& r) { r.ramp_speed_limit_mps = NaN; }, "ramp_speed_limit_mps", "nan");
}

TEST(RoadSpec, ZoneBoundariesAreMultiplesOfTheClusterLength) {
  EXPECT_EQ(palcas::sim::zoneBoundaries(RoadSpec{}), (std::vector<double>{0, 800, 1600, 2400}));
  EXPECT_EQ(palcas::sim::zoneBoundaries(palcas::sim::test::tinyRoad()),
            (std::vector<double>{0, 300, 600}));
  RoadSpec bad;
  bad.clusters = 0;
  EXPECT_THROW(palcas::sim::zoneBoundaries(bad), std::invalid_argument);
}

TEST(RoadSpec, WritesTheThreeSourcesWithTheRoadsGeometry) {
  const std::string dir = freshDir("road_sources") + "/nested/sources";  // created
  palcas::sim::writeNetworkSources(RoadSpec{}, dir);
  const std::string nodes = slurp(dir + "/network.nod.xml");
  const std::string edges = slurp(dir + "/network.edg.xml");
  const std::string links = slurp(dir + "/network.con.xml");
  // Node shapes reach across the merge edge's L + 1 = 6 lanes of 3.2 m.
  EXPECT_NE(nodes.find("<node id=\"n_0_diverge\" x=\"700\" y=\"0\" shape=\"700,0 700,-19.2\"/>"),
            std::string::npos);
  EXPECT_NE(nodes.find("<node id=\"n_end\" x=\"2400\" y=\"0\"/>"), std::string::npos);
  // On-ramp: 1.25 road widths (20 m) below the acceleration lane's centre (-17.6), 30 m parallel.
  EXPECT_NE(edges.find("shape=\"800,-37.6 920,-17.6 950,-17.6\""), std::string::npos);
  // Off-ramp: from SUMO lane 0's centre (-14.4) down 20 m over the last 100 m.
  EXPECT_NE(edges.find("shape=\"2300,-14.4 2400,-34.4\""), std::string::npos);
  EXPECT_NE(links.find("<connection from=\"on_2\" to=\"main_2_merge\" fromLane=\"0\" toLane=\"0\"/>"),
            std::string::npos);
}

TEST(RoadSpec, PaperAndTinySourcesAreTheHandWrittenOnesTagForTag) {
  // Stronger than the network comparison (scenario_network_test): the ramp shapes and node y
  // are pinned too, so the geometry formula of road_spec.h is the one of the former sources.
  for (const auto& [name, spec] :
       {std::pair<std::string, RoadSpec>{"paper", RoadSpec{}}, {"tiny", palcas::sim::test::tinyRoad()}}) {
    const std::string dir = freshDir("tag_for_tag_" + name);
    palcas::sim::writeNetworkSources(spec, dir);
    for (const char* f : {"network.nod.xml", "network.edg.xml", "network.con.xml"})
      EXPECT_EQ(withoutComments(slurp(dir + "/" + f)),
                withoutComments(slurp(palcas::sim::test::handWrittenDir(name) + "/" + f)))
          << name << " " << f;
  }
}

TEST(RoadSpec, UnwritableFolderIsARuntimeErrorNamingThePath) {
  const std::string file = freshDir("road_unwritable") + "/a_file";
  std::ofstream(file) << "not a folder";
  palcas_test::expectThrowNaming<std::runtime_error>(
      [&] { palcas::sim::writeNetworkSources(RoadSpec{}, file + "/sources"); }, file + "/sources");
}
