#include "palcas_sim/run_recorder.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

namespace palcas::sim {
namespace {

std::vector<std::string> lines(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::string> out;
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

class RunRecorderTest : public ::testing::Test {
 protected:
  std::string dir_ = std::filesystem::temp_directory_path().string() + "/palcas_run_recorder_" +
                     std::to_string(::getpid());
  void TearDown() override { std::filesystem::remove_all(dir_); }
};

VehicleRecord vehicle(const std::string& id, bool cav) {
  VehicleRecord v;
  v.id = id;
  v.is_cav = cav;
  v.route_kind = cav ? RouteKind::kMainExit : RouteKind::kMainThrough;
  v.exit_cluster = cav ? 1 : -1;
  v.part = RoadPart::kMainline;
  v.x_m = 120.5;
  v.lane = 2;
  v.speed_mps = 25.0;
  v.accel_mps2 = -1.5;
  return v;
}

TEST_F(RunRecorderTest, SamplesEveryPeriodAndWritesEveryVehicle) {
  {
    RunRecorder rec(dir_, 5);
    VehicleRecord cav = vehicle("c0", true);
    cav.command = HeldCommand::kAccelerate;
    cav.command_value = 1.2;
    const std::vector<VehicleRecord> road = {cav, vehicle("h0", false)};
    for (std::uint64_t step = 1; step <= 12; ++step) rec.addStep(step, 0.1 * step, road);
    EXPECT_EQ(rec.trajectoryRows(), 4u);  // steps 5 and 10, two vehicles each
    rec.addDecision(1.0, "rsu_0", 0.8, 3);
    rec.close();
  }
  const auto traj = lines(dir_ + "/trajectories.csv");
  ASSERT_EQ(traj.size(), 5u);
  EXPECT_EQ(traj[0], RunRecorder::kTrajectoryHeader);
  EXPECT_EQ(traj[1], "0.5,c0,1,main_exit,1,mainline,120.5,2,25,-1.5,accelerate,1.2,0");
  EXPECT_EQ(traj[2], "0.5,h0,0,main_through,-1,mainline,120.5,2,25,-1.5,none,0,0");
  const auto dec = lines(dir_ + "/decisions.csv");
  ASSERT_EQ(dec.size(), 2u);
  EXPECT_EQ(dec[1], "1,rsu_0,0.8,3");
}

TEST_F(RunRecorderTest, RejectsABadPeriodAndAnUnwritableFolder) {
  EXPECT_THROW(RunRecorder(dir_, 0), std::invalid_argument);
  std::filesystem::create_directories(dir_);
  std::ofstream(dir_ + "/file") << "x";
  EXPECT_ANY_THROW(RunRecorder(dir_ + "/file/sub", 1));
}

}  // namespace
}  // namespace palcas::sim
