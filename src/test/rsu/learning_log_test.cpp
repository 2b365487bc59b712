#include "palcas_core/rsu/learning_log.h"

#include <gtest/gtest.h>

#include "common/throws_naming.h"

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

using palcas::rsu::LearningLog;
using palcas::rsu::RsuControllerStats;

namespace {

std::vector<std::string> lines(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::string> out;
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

RsuControllerStats decision(uint32_t transitions, double reward_sum, uint64_t gradient_steps) {
  RsuControllerStats s;
  s.transitions_closed = transitions;
  s.sum_reward = reward_sum;
  s.gradient_steps = gradient_steps;
  s.epsilon = 0.5;
  s.model_version = 3;
  s.federation_round = 2;
  return s;
}

std::string freshPath(const std::string& name) {
  const std::string dir = testing::TempDir() + "/palcas_learning_log_" + name;
  std::filesystem::remove_all(dir);
  return dir + "/rsu_0/learning.csv";  // the folder does not exist yet
}

}  // namespace

TEST(LearningLog, OneRowPerEpisodeWithItsSumsAndMeans) {
  const std::string path = freshPath("rows");
  LearningLog log(path, "rsu_0", "train");
  log.addDecision(10, decision(2, -1.0, 5), 1.0);
  log.addDecision(20, decision(2, -3.0, 6), 3.0);
  EXPECT_EQ(log.decisions(), 2u);
  log.endEpisode(decision(0, 0.0, 7));
  const auto rows = lines(path);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0], LearningLog::header());
  // decisions 2, transitions 4, mean -1, sum -4, eps 0.5, steps 7, losses NaN, v3, round 2, 2 ms
  EXPECT_EQ(rows[1], "rsu_0,train,2,4,-1,-4,0.5,7,nan,nan,3,2,2");
}

TEST(LearningLog, AStepThatGoesBackClosesTheEpisode) {
  const std::string path = freshPath("restart");
  LearningLog log(path, "rsu_1", "eval");
  log.addDecision(100, decision(1, -1.0, 0), 1.0);
  log.addDecision(200, decision(1, -1.0, 0), 1.0);
  log.addDecision(0, decision(1, -2.0, 0), 1.0);  // the bridge began the next episode
  EXPECT_EQ(log.decisions(), 1u);
  log.endEpisode(decision(0, 0.0, 0));
  log.endEpisode(decision(0, 0.0, 0));  // nothing open: no third row
  const auto rows = lines(path);
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[1].rfind("rsu_1,eval,2,2,-1,-2,", 0), 0u) << rows[1];
  EXPECT_EQ(rows[2].rfind("rsu_1,eval,1,1,-2,-2,", 0), 0u) << rows[2];
}

TEST(LearningLog, AppendsToAnExistingFileWithoutASecondHeader) {
  const std::string path = freshPath("append");
  for (int run = 0; run < 2; ++run) {  // a resumed training opens the file again
    LearningLog log(path, "rsu_0", "train");
    log.addDecision(1, decision(0, 0.0, 0), 1.0);
    log.endEpisode(decision(0, 0.0, 0));
  }
  const auto rows = lines(path);
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[0], LearningLog::header());
  EXPECT_NE(rows[2], LearningLog::header());
  // No transitions: the mean reward is NaN, not a division by zero.
  EXPECT_EQ(rows[2].rfind("rsu_0,train,1,0,nan,0,", 0), 0u) << rows[2];
}

TEST(LearningLog, NoPathKeepsFiguresAndWritesNothing) {
  LearningLog log("", "rsu_0", "train");
  log.addDecision(1, decision(1, -1.0, 0), 1.0);
  EXPECT_EQ(log.decisions(), 1u);
  log.endEpisode(decision(0, 0.0, 0));
  EXPECT_EQ(log.decisions(), 0u);
}

TEST(LearningLog, AnUnwritableFileIsNamed) {
  const std::string dir = testing::TempDir() + "/palcas_learning_log_blocked";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir + "/learning.csv");  // a folder where the file goes
  LearningLog log(dir + "/learning.csv", "rsu_0", "train");
  log.addDecision(1, decision(1, -1.0, 0), 1.0);
  palcas_test::expectThrowNaming<std::runtime_error>(
      [&] { log.endEpisode(decision(0, 0.0, 0)); }, dir + "/learning.csv");
}
