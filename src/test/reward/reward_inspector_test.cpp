// Runs the palcas_reward binary on a few lines, including malformed ones.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

struct InspectorRun {
  int status = -1;
  std::vector<std::string> lines;
};

// Writes `input` to a temporary file and runs the inspector on it with `args`.
InspectorRun runInspector(const std::string& input, const std::string& args = "") {
  const std::string path = ::testing::TempDir() + "palcas_reward_input.jsonl";
  std::ofstream(path) << input;
  const std::string cmd =
      std::string(PALCAS_REWARD_BIN) + " " + args + " < " + path + " 2>/dev/null";
  InspectorRun run;
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) return run;
  std::string out;
  char buffer[4096];
  while (size_t n = fread(buffer, 1, sizeof buffer, pipe)) out.append(buffer, n);
  const int raw = pclose(pipe);
  run.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  std::istringstream in(out);
  for (std::string line; std::getline(in, line);) run.lines.push_back(line);
  return run;
}

const char* const GOOD =
    R"({"v": 20, "a": 0, "lane": 1, "num_lanes": 5, "length": 5, "distance_to_exit": null,)"
    R"( "lead": {"gap": 10, "v": 18}, "follow": null, "lateral": null, "target_lead": null,)"
    R"( "target_follow": null, "cluster_mean_speed": 20, "accel_lane": null})";

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

}  // namespace

TEST(RewardInspector, PrintsEveryComponent) {
  const InspectorRun run = runInspector(std::string(GOOD) + "\n");
  EXPECT_EQ(run.status, 0);
  ASSERT_EQ(run.lines.size(), 1u);
  const std::string& out = run.lines[0];
  for (const char* key : {"delta_long_lead", "delta_long_follow", "\"p\"", "tau_need", "tau_tte",
                          "\"u\"", "\"w\"", "p_stage", "r_e", "r_s", "r_c", "r_lc", "r_d", "total"})
    EXPECT_TRUE(contains(out, key)) << key << " missing in " << out;
  // delta = 14.8376 (see reward_test); no exit -> tau_tte "inf"; no follower -> null;
  // lane 1, no exit: r_lc = p_stage = -1
  EXPECT_TRUE(contains(out, "\"delta_long_lead\":14.8376")) << out;
  EXPECT_TRUE(contains(out, "\"delta_long_follow\":null")) << out;
  EXPECT_TRUE(contains(out, "\"tau_tte\":\"inf\"")) << out;
  EXPECT_TRUE(contains(out, "\"r_lc\":-1.0")) << out;
}

TEST(RewardInspector, MalformedLinesAreReportedAndTheRestProcessed) {
  std::string missing_key = GOOD;
  missing_key.replace(missing_key.find("\"a\": 0, "), 8, "");
  std::string wrong_type = GOOD;
  wrong_type.replace(wrong_type.find("\"lane\": 1"), 9, "\"lane\": \"1\"");
  std::string overflow = GOOD;  // 1e999 does not fit a double: nlohmann's parser rejects it
  overflow.replace(overflow.find("\"v\": 20"), 7, "\"v\": 1e999");
  std::string nan_value = GOOD;  // JSON has no NaN: a parse error naming the position
  nan_value.replace(nan_value.find("\"a\": 0"), 6, "\"a\": NaN");
  const InspectorRun run = runInspector("{not json\n" + missing_key + "\n\n" + wrong_type + "\n" +
                                        overflow + "\n" + GOOD + "\n" + nan_value + "\n");
  EXPECT_EQ(run.status, 1);
  ASSERT_EQ(run.lines.size(), 6u);  // the blank line 3 is skipped
  EXPECT_TRUE(contains(run.lines[0], "\"line\":1,\"error\"")) << run.lines[0];
  EXPECT_TRUE(contains(run.lines[1], "\"line\":2,\"error\"") && contains(run.lines[1], "'a'"))
      << run.lines[1];
  EXPECT_TRUE(contains(run.lines[2], "\"line\":4,\"error\"") && contains(run.lines[2], "'lane'"))
      << run.lines[2];
  EXPECT_TRUE(contains(run.lines[3], "\"line\":5,\"error\"") && contains(run.lines[3], "1e999"))
      << run.lines[3];
  EXPECT_TRUE(contains(run.lines[4], "\"line\":6,") && contains(run.lines[4], "total"))
      << run.lines[4];
  EXPECT_TRUE(contains(run.lines[5], "\"line\":7,\"error\"") && contains(run.lines[5], "parse"))
      << run.lines[5];
}

TEST(RewardInspector, ParamOverridesAndUnknownNames) {
  // lambda = 0 (the ablation): r_lc stays -1 but no longer enters the total.
  const InspectorRun ablated = runInspector(std::string(GOOD) + "\n", "--param lambda=0");
  ASSERT_EQ(ablated.lines.size(), 1u);
  EXPECT_EQ(ablated.status, 0);
  // total = 0.05 r_e + 0.5 r_s + 0.05 r_c: r_e = 0.5(-13.528/33.528)*2 = -0.403484,
  // r_s = -0.326037, r_c = 0.773684 -> -0.020174 - 0.163018 + 0.038684 = -0.144508
  EXPECT_TRUE(contains(ablated.lines[0], "\"total\":-0.14450")) << ablated.lines[0];
  const InspectorRun unknown = runInspector(std::string(GOOD) + "\n", "--param lamda=0");
  EXPECT_EQ(unknown.status, 2);
  EXPECT_TRUE(unknown.lines.empty());
}
