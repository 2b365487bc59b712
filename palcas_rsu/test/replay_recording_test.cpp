// readRecording (palcas_rsu/replay_recording.h) on bags this test writes itself: what it
// reads from a recorded episode, and each way a bag is refused, naming what it lacks.
#include "palcas_rsu/replay_recording.h"

#include <gtest/gtest.h>
#include <palcas_msgs/RoadDescription.h>
#include <palcas_msgs/VehicleStateArray.h>
#include <rosbag/bag.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

using palcas::rsu::readRecording;
using palcas::rsu::Recording;
using palcas::rsu::ReplayInputError;

namespace {

/// A fresh path under the test's temporary folder.
std::string tempPath(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / "palcas_replay_recording_test";
  std::filesystem::create_directories(dir);
  return (dir / name).string();
}

palcas_msgs::VehicleStateArray states(std::uint64_t step, int lanes = 5) {
  palcas_msgs::VehicleStateArray s;
  s.header.stamp = ros::Time(0.1 * static_cast<double>(step) + 1e-3);
  s.step = step;
  s.step_length_s = 0.1;
  s.num_lanes = static_cast<std::uint8_t>(lanes);
  return s;
}

palcas_msgs::AdvisoryArray answer(std::uint64_t step, const std::string& rsu) {
  palcas_msgs::AdvisoryArray a;
  a.header.stamp = ros::Time(0.1 * static_cast<double>(step) + 1e-3);
  a.step = step;
  a.rsu_id = rsu;
  return a;
}

palcas_msgs::ClusterState cluster(double t, const std::string& rsu, int k, double from, double to) {
  palcas_msgs::ClusterState c;
  c.header.stamp = ros::Time(t);
  c.rsu_id = rsu;
  c.cluster_index = static_cast<std::uint8_t>(k);
  c.x_start_m = from;
  c.x_end_m = to;
  return c;
}

/// A bag of two RSUs over 20 steps; `edit` changes what goes in.
struct BagContents {
  bool road = true;
  int road_lanes = 5;
  bool advisories = true;
  bool clusters = true;
  bool gap_in_clusters = false;  // cluster states of zones 0 and 2 only
};

std::string writeBag(const std::string& name, const BagContents& c) {
  const std::string path = tempPath(name + ".bag");
  rosbag::Bag bag(path, rosbag::bagmode::Write);
  const ros::Time t0(1e-3);
  if (c.road) {
    palcas_msgs::RoadDescription r;
    r.header.stamp = t0;
    r.zone_boundaries_m = {0.0, 800.0, 1600.0};
    r.num_lanes = static_cast<std::uint8_t>(c.road_lanes);
    r.step_length_s = 0.1;
    bag.write("/road_description", t0, r);
  }
  for (std::uint64_t step = 0; step < 20; ++step) {
    const auto s = states(step);
    bag.write("/vehicle_states", s.header.stamp, s);
    if (c.advisories && step % 10 == 0)
      for (const char* rsu : {"rsu_0", "rsu_1"}) bag.write("/advisories", s.header.stamp, answer(step, rsu));
  }
  if (c.clusters) {
    // Written out of time order: the reader sorts them by stamp.
    bag.write("/cluster_states", ros::Time(1.5), cluster(1.5, "rsu_0", 0, 0.0, 800.0));
    bag.write("/cluster_states", ros::Time(1.2),
              c.gap_in_clusters ? cluster(1.2, "rsu_1", 2, 1600.0, 2400.0) : cluster(1.2, "rsu_1", 1, 800.0, 1600.0));
    bag.write("/cluster_states", ros::Time(1.4), cluster(1.4, "rsu_0", 0, 0.0, 800.0));
  }
  bag.close();
  return path;
}

void expectRefused(const std::function<void()>& call, const std::string& needle) {
  try {
    call();
    ADD_FAILURE() << "not refused; expected an error naming: " << needle;
  } catch (const ReplayInputError& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

}  // namespace

TEST(ReplayRecording, ReadsTheRoadTheRsusTheirAdviceAndTheClusterStatesInTimeOrder) {
  const Recording rec = readRecording(writeBag("whole", {}));
  EXPECT_EQ(rec.road.zones_m, (std::vector<double>{0.0, 800.0, 1600.0}));
  EXPECT_EQ(rec.road.num_lanes, 5);
  EXPECT_EQ(rec.road.source, "/road_description");
  EXPECT_EQ(rec.state_size, 45);
  EXPECT_DOUBLE_EQ(rec.step_length_s, 0.1);
  EXPECT_EQ(rec.rsu_ids, (std::set<std::string>{"rsu_0", "rsu_1"}));
  EXPECT_EQ(rec.advisories.size(), 4u);
  EXPECT_EQ(rec.advisories.count({10, "rsu_1"}), 1u);
  ASSERT_EQ(rec.cluster_states.size(), 3u);
  EXPECT_DOUBLE_EQ(rec.cluster_states[0].header.stamp.toSec(), 1.2);
  EXPECT_DOUBLE_EQ(rec.cluster_states[2].header.stamp.toSec(), 1.5);
  EXPECT_EQ(rec.cluster_of.at("rsu_1"), 1);
  EXPECT_TRUE(rec.i2i);
}

TEST(ReplayRecording, AnOlderBagsZonesComeFromItsClusterStates) {
  BagContents c;
  c.road = false;
  const Recording rec = readRecording(writeBag("no_road", c));
  EXPECT_EQ(rec.road.zones_m, (std::vector<double>{0.0, 800.0, 1600.0}));
  EXPECT_EQ(rec.road.num_lanes, 5) << "the states' lane count";
  EXPECT_NE(rec.road.source.find("no /road_description"), std::string::npos) << rec.road.source;
  BagContents without_i2i;
  without_i2i.clusters = false;
  EXPECT_FALSE(readRecording(writeBag("no_i2i", without_i2i)).i2i) << "no cluster states: the RSUs ran without I2I";
}

TEST(ReplayRecording, ABagUnfitForReplayIsRefusedNamingWhatItLacks) {
  expectRefused([] { readRecording(tempPath("absent.bag")); }, "absent.bag': no such file");
  const std::string text = tempPath("not_a_bag.bag");
  std::ofstream(text) << "plain text";
  expectRefused([&] { readRecording(text); }, "is not a bag");
  BagContents c;
  c.advisories = false;
  expectRefused([&] { readRecording(writeBag("no_advice", c)); }, "lacks /advisories");
  c = BagContents{};
  c.road_lanes = 4;
  expectRefused([&] { readRecording(writeBag("lanes", c)); }, "road has 4 lanes but its /vehicle_states say 5");
  c = BagContents{};
  c.road = false;
  c.gap_in_clusters = true;
  expectRefused([&] { readRecording(writeBag("gap", c)); }, "do not give every zone");
}
