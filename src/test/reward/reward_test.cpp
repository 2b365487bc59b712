#include "palcas_core/reward/reward.h"

#include <gtest/gtest.h>

#include "common/throws_naming.h"

#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <regex>
#include <stdexcept>

using palcas::CavSituation;
using palcas::computeReward;
using palcas::RewardParams;

namespace {

constexpr double INF = std::numeric_limits<double>::infinity();

// A quiet CAV: lane 1 of 5, 20 m/s, no exit, no neighbours, cluster at 20 m/s.
CavSituation quiet() {
  CavSituation s;
  s.v = 20.0;
  s.a = 0.0;
  s.lane = 1;
  s.num_lanes = 5;
  s.length = 5.0;
  s.distance_to_exit = INF;
  s.cluster_mean_speed = 20.0;
  return s;
}

// Expects std::invalid_argument whose message names `key`.
void expectRejected(const CavSituation& s, const std::string& key) {
  palcas_test::expectThrowNaming<std::invalid_argument>(
      [&] { computeReward(s, RewardParams()); }, "'" + key + "'");
}

}  // namespace

TEST(Reward, DefaultsEqualThePapersValues) {
  const RewardParams p;
  EXPECT_EQ(p.iota, 0.05);
  EXPECT_EQ(p.zeta, 0.5);
  EXPECT_EQ(p.xi, 0.05);
  EXPECT_EQ(p.lambda, 0.4);
  EXPECT_EQ(p.psi, 0.1);
  EXPECT_EQ(p.w_c, 0.5);
  EXPECT_EQ(p.w_e, 0.5);  // not in the paper: our choice
  EXPECT_EQ(p.v_max_ego, 33.528);
  EXPECT_EQ(p.v_min_ego, 0.0);
  EXPECT_EQ(p.v_bar_max, 33.528);
  EXPECT_EQ(p.v_bar_min, 0.0);
  EXPECT_EQ(p.rho, 0.2);
  EXPECT_EQ(p.a_max, 2.6);
  EXPECT_EQ(p.a_b_min, 4.5);
  EXPECT_EQ(p.a_b_max, 4.5);
  EXPECT_EQ(p.mu, 0.1);
  EXPECT_EQ(p.a_b_lat, 1.0);
  EXPECT_EQ(p.a_lat_max, 1.0);
  EXPECT_EQ(p.a_th, 1.47);
  EXPECT_EQ(p.a_min, -4.5);
  EXPECT_EQ(p.d_th, 50.0);
  EXPECT_EQ(p.v_th, 5.0);
  EXPECT_EQ(p.tau0, 2.0);
  EXPECT_EQ(p.epsilon, 1e-6);
  EXPECT_EQ(p.ttc_star, 1.5);
  EXPECT_EQ(p.sigma_ttc, 0.1);
  EXPECT_EQ(p.exit_scale, 1000.0);
  EXPECT_EQ(p.beta, 10.0);
  // The paper's 28 constants plus the 4 switches of our departures (0 = the paper).
  EXPECT_EQ(palcas::rewardParamNames().size(), 32u);
}

TEST(Reward, EfficiencyCombinesEgoAndCluster) {
  CavSituation s = quiet();
  s.cluster_mean_speed = 30.0;
  const auto r = computeReward(s, RewardParams());
  // r_ego = -|20 - 33.528| / 33.528 = -13.528/33.528 = -0.403484
  // r_cluster = -|30 - 33.528| / 33.528 = -3.528/33.528 = -0.105225
  // r_e = 0.5*(-0.403484) + 0.5*(-0.105225) = -0.254355
  EXPECT_NEAR(r.r_ego, -0.4034837, 1e-6);
  EXPECT_NEAR(r.r_cluster, -0.1052255, 1e-6);
  EXPECT_NEAR(r.r_e, -0.2543546, 1e-6);
}

TEST(Reward, EfficiencyUsesOwnMaxSpeedAndPenalisesSpeeding) {
  CavSituation s = quiet();
  s.v = 33.0;
  s.v_max = 30.0;
  // r_ego = -|33 - 30| / (30 - 0) = -0.1 (above v_max is penalised too)
  EXPECT_NEAR(computeReward(s, RewardParams()).r_ego, -0.1, 1e-12);
}

TEST(Reward, SafetyLeadPairUsesEgoAsRear) {
  CavSituation s = quiet();
  s.lead = CavSituation::GapSpeed{10.0, 18.0};
  const auto r = computeReward(s, RewardParams());
  // delta = 4 + 0.052 + 46.7856 - 36 = 14.8376; (10 - 14.8376)/14.8376 = -0.326037
  ASSERT_TRUE(r.delta_long_lead.has_value());
  EXPECT_NEAR(*r.delta_long_lead, 14.8376, 1e-9);
  EXPECT_FALSE(r.delta_long_follow.has_value());
  EXPECT_NEAR(r.r_s, -0.3260366, 1e-6);
}

TEST(Reward, SafetyFollowPairUsesFollowerAsRear) {
  CavSituation s = quiet();
  s.follow = CavSituation::GapSpeed{5.0, 22.0};
  const auto r = computeReward(s, RewardParams());
  // delta = 22*0.2 + 0.052 + 22.52^2/9 - 20^2/9 = 4.4 + 0.052 + 56.350044 - 44.444444 = 16.3576
  // (5 - 16.3576)/16.3576 = -0.694332
  ASSERT_TRUE(r.delta_long_follow.has_value());
  EXPECT_NEAR(*r.delta_long_follow, 16.3576, 1e-9);
  EXPECT_NEAR(r.r_s_long, -0.6943317, 1e-6);
}

TEST(Reward, SafetyWithoutNeighboursHasNoTerm) {
  const auto r = computeReward(quiet(), RewardParams());
  EXPECT_FALSE(r.delta_long_lead.has_value());
  EXPECT_TRUE(r.delta_lat.empty());
  EXPECT_EQ(r.r_s, 0.0);
}

TEST(Reward, SafetySatisfiedGapGivesZero) {
  CavSituation s = quiet();
  s.lead = CavSituation::GapSpeed{100.0, 18.0};  // 100 > 14.8376 -> min(+, 0) = 0
  EXPECT_EQ(computeReward(s, RewardParams()).r_s, 0.0);
}

TEST(Reward, SafetyZeroDeltaIsSatisfiedUnlessOverlapping) {
  CavSituation s = quiet();
  s.v = 0.0;
  s.lead = CavSituation::GapSpeed{1.0, 10.0};  // delta = 0 (see Rss test): gap 1 >= 0 -> 0
  EXPECT_EQ(computeReward(s, RewardParams()).r_s, 0.0);
  s.lead->gap = -0.5;  // overlap with delta = 0 -> -1
  EXPECT_EQ(computeReward(s, RewardParams()).r_s, -1.0);
}

TEST(Reward, SafetyOverlapWithPositiveDelta) {
  CavSituation s = quiet();
  s.lead = CavSituation::GapSpeed{-2.0, 18.0};  // (-2 - 14.8376)/14.8376 = -1.134793
  EXPECT_NEAR(computeReward(s, RewardParams()).r_s, -1.1347927, 1e-6);
}

TEST(Reward, SafetyLateralSumsOverNeighbours) {
  CavSituation s = quiet();
  // delta(0, 0) = 0.14: (0.07 - 0.14)/0.14 = -0.5
  // delta(1, -0.5) = 1.165: gap 2 >= 1.165 -> 0
  s.lateral = {{0.07, 0.0, 0.0}, {2.0, 1.0, -0.5}};
  const auto r = computeReward(s, RewardParams());
  ASSERT_EQ(r.delta_lat.size(), 2u);
  EXPECT_NEAR(r.delta_lat[0], 0.14, 1e-12);
  EXPECT_NEAR(r.delta_lat[1], 1.165, 1e-12);
  EXPECT_NEAR(r.r_s_lat, -0.5, 1e-12);
  EXPECT_NEAR(r.r_s, -0.5, 1e-12);
}

TEST(Reward, ComfortRewardsSmallAndPenalisesLargeAcceleration) {
  CavSituation s = quiet();
  // (1.47 - 0) / (4.5 - 2.6) = 1.47/1.9 = 0.773684
  EXPECT_NEAR(computeReward(s, RewardParams()).r_c, 0.7736842, 1e-6);
  s.a = -3.0;  // (1.47 - 3)/1.9 = -1.53/1.9 = -0.805263
  EXPECT_NEAR(computeReward(s, RewardParams()).r_c, -0.8052632, 1e-6);
}

TEST(Reward, PriorityWithoutExitPenalisesOnlyTheExitLane) {
  CavSituation s = quiet();
  // No exit: sigma(inf) = 1, so w = 2(1 - 1)(n/4) = 0 and p_stage = -2(1 - 0.5)(1 - n/4).
  auto r = computeReward(s, RewardParams());  // lane 1: n = 0 -> p_stage = -1
  EXPECT_TRUE(std::isinf(r.tau_tte));
  EXPECT_EQ(r.w, 0.0);
  EXPECT_EQ(r.u * r.w, 0.0);
  EXPECT_DOUBLE_EQ(r.p_stage, -1.0);
  EXPECT_DOUBLE_EQ(r.r_lc, -1.0);
  s.lane = 3;  // n = 2: p_stage = -(1 - 2/4) = -0.5
  EXPECT_DOUBLE_EQ(computeReward(s, RewardParams()).r_lc, -0.5);
  s.lane = 5;  // n = 4: p_stage = -(1 - 1) = 0
  EXPECT_DOUBLE_EQ(computeReward(s, RewardParams()).r_lc, 0.0);
}

TEST(Reward, PriorityUrgencyComparesTimeToExitWithTimeNeeded) {
  CavSituation s = quiet();
  s.lane = 3;
  s.distance_to_exit = 60.0;  // free target lane -> p-ttc = +inf -> p = 1
  const auto r = computeReward(s, RewardParams());
  // n = 2, tau_need = 2*2/(1 + 1e-6) = 3.999996; tau_tte = 60/(20 + 1e-6) = 2.99999985
  // u = -1/(1 + exp(2.99999985 - 3.999996)) = -1/(1 + exp(-0.99999615)) = -0.731058
  // sigma(60/1000) = sigma(0.06) = 0.514996
  // w = 2(1 - 0.514996)(2/4) = 0.485004; p_stage = -2(0.514996 - 0.5)(1 - 0.5) = -0.014996
  // r_lc = -0.731058*0.485004 - 0.014996 = -0.354566 - 0.014996 = -0.369562
  EXPECT_TRUE(std::isinf(r.p_ttc_min));
  EXPECT_EQ(r.p, 1.0);
  EXPECT_NEAR(r.tau_need, 3.999996, 1e-9);
  EXPECT_NEAR(r.tau_tte, 2.99999985, 1e-9);
  EXPECT_NEAR(r.u, -0.7310578, 1e-6);
  EXPECT_NEAR(r.w, 0.4850045, 1e-6);
  EXPECT_NEAR(r.p_stage, -0.0149955, 1e-6);
  EXPECT_NEAR(r.r_lc, -0.3695618, 1e-6);
}

TEST(Reward, PriorityCloseAndSlowUsesMinusP) {
  CavSituation s = quiet();
  s.lane = 2;
  s.v = 3.0;
  s.distance_to_exit = 30.0;  // 30 < 50 and 3 < 5 -> u = -p
  s.target_lead = CavSituation::TargetLead{10.0, 1.0, 5.0};
  const auto r = computeReward(s, RewardParams());
  // p-ttc = (10 - 5)/(3 - 1) = 2.5; p = sigma((2.5 - 1.5)/0.1) = sigma(10) = 0.9999546
  EXPECT_NEAR(r.p_ttc_min, 2.5, 1e-12);
  EXPECT_NEAR(r.p, 0.9999546, 1e-7);
  EXPECT_DOUBLE_EQ(r.u, -r.p);
}

TEST(Reward, FeasibilityTakesTheSmallerProjectedTtc) {
  CavSituation s = quiet();
  s.lane = 2;
  s.distance_to_exit = 500.0;
  s.target_lead = CavSituation::TargetLead{30.0, 10.0, 5.0};  // (30-5)/(20-10) = 2.5 s
  s.target_follow = CavSituation::TargetFollow{12.0, 25.0};   // (12-5)/(25-20) = 1.4 s
  const auto r = computeReward(s, RewardParams());
  // min = 1.4; p = sigma((1.4 - 1.5)/0.1) = sigma(-1) = 0.268941
  EXPECT_NEAR(r.p_ttc_min, 1.4, 1e-12);
  EXPECT_NEAR(r.p, 0.2689414, 1e-6);
  // tau_need = 1*2/(0.268941 + 1e-6) = 7.436502
  EXPECT_NEAR(r.tau_need, 2.0 / (0.2689414213699951 + 1e-6), 1e-9);
  EXPECT_NEAR(r.tau_need, 7.43650, 1e-4);
}

TEST(Reward, FeasibilityIsOneWhenNobodyClosesIn) {
  CavSituation s = quiet();
  s.lane = 2;
  s.target_lead = CavSituation::TargetLead{30.0, 25.0, 5.0};  // lead faster -> +inf
  s.target_follow = CavSituation::TargetFollow{12.0, 15.0};   // follower slower -> +inf
  const auto r = computeReward(s, RewardParams());
  EXPECT_TRUE(std::isinf(r.p_ttc_min));
  EXPECT_EQ(r.p, 1.0);  // sigma(+inf) = 1
}

TEST(Reward, FeasibilityIsNilWhenTheTargetSpotIsOccupied) {
  CavSituation s = quiet();
  s.lane = 2;
  // Front-to-front 3 m with a 5 m leader: overlap; the leader is faster, but p-ttc = 0.
  s.target_lead = CavSituation::TargetLead{3.0, 25.0, 5.0};
  const auto r = computeReward(s, RewardParams());
  // p = sigma((0 - 1.5)/0.1) = sigma(-15) = 3.059e-7
  EXPECT_EQ(r.p_ttc_min, 0.0);
  EXPECT_NEAR(r.p, 3.059022e-7, 1e-12);
}

TEST(Reward, OneLaneRoadHasNoStagingAndNoUrgencyOnTheMainline) {
  CavSituation s = quiet();
  s.num_lanes = 1;
  s.distance_to_exit = 200.0;
  auto r = computeReward(s, RewardParams());  // lane 1: n = 0 -> LC factor 0, p_stage 0
  EXPECT_EQ(r.lc_factor, 0.0);
  EXPECT_EQ(r.w, 0.0);
  EXPECT_EQ(r.p_stage, 0.0);
  EXPECT_EQ(r.r_lc, 0.0);
  s.lane = 0;  // ramp on a one-lane road: n = 1 -> LC factor min(1, 1) = 1
  s.accel_lane = CavSituation::AccelLane{100.0, 200.0};
  r = computeReward(s, RewardParams());
  // w = 2 sigma(-0.2) * 1 = 2 * 0.450166 = 0.900332
  EXPECT_EQ(r.lc_factor, 1.0);
  EXPECT_NEAR(r.w, 0.9003320, 1e-6);
  EXPECT_EQ(r.p_stage, 0.0);
}

TEST(Reward, RampVehicleIsOneLaneChangeFromTheExitLane) {
  CavSituation s = quiet();
  s.lane = 0;
  s.distance_to_exit = INF;
  const auto r = computeReward(s, RewardParams());
  // n = |0 - 1| = 1; LC factor 1/4; p_stage = -(1 - 0.25) = -0.75
  EXPECT_EQ(r.n, 1);
  EXPECT_DOUBLE_EQ(r.lc_factor, 0.25);
  EXPECT_DOUBLE_EQ(r.p_stage, -0.75);
}

TEST(Reward, DeadlockPenaltyGrowsTowardTheEndOfTheAccelerationLane) {
  CavSituation s = quiet();
  s.lane = 0;
  s.accel_lane = CavSituation::AccelLane{150.0, 200.0};
  // -exp(-(150 - 200)^2 / (10*200)) = -exp(-2500/2000) = -exp(-1.25) = -0.286505
  EXPECT_NEAR(computeReward(s, RewardParams()).r_d, -0.2865048, 1e-6);
  s.accel_lane->x = 200.0;  // at the end: -exp(0) = -1
  EXPECT_DOUBLE_EQ(computeReward(s, RewardParams()).r_d, -1.0);
  s.accel_lane.reset();  // not on an acceleration lane: 0
  EXPECT_EQ(computeReward(s, RewardParams()).r_d, 0.0);
}

TEST(Reward, TotalIsTheWeightedSum) {
  CavSituation s = quiet();
  s.cluster_mean_speed = 30.0;                           // r_e = -0.2543546 (see Efficiency test)
  s.lead = CavSituation::GapSpeed{10.0, 18.0};           // r_s = -0.3260366
  s.a = -3.0;                                            // r_c = -0.8052632
  s.lane = 0;                                            // no exit: r_lc = p_stage = -0.75
  s.accel_lane = CavSituation::AccelLane{150.0, 200.0};  // r_d = -0.2865048
  const auto r = computeReward(s, RewardParams());
  // 0.05*(-0.2543546) + 0.5*(-0.3260366) + 0.05*(-0.8052632) + 0.4*(-0.75) + 0.1*(-0.2865048)
  // = -0.0127177 - 0.1630183 - 0.0402632 - 0.3 - 0.0286505 = -0.5446497
  EXPECT_NEAR(r.total, -0.5446497, 1e-6);
}

TEST(Reward, ExtremeValuesStayFinite) {
  CavSituation s = quiet();
  s.lane = 5;
  s.v = 0.0;
  s.distance_to_exit = 1e6;  // tau_tte = 1e6/1e-6 = 1e12: exp(1e12) would overflow
  auto r = computeReward(s, RewardParams());
  EXPECT_TRUE(std::isfinite(r.r_lc));
  EXPECT_EQ(r.u, 0.0);  // p = 1: tau_need = 4*2/(1 + 1e-6) ~ 8; u = -sigma(8 - 1e12) = -0
  RewardParams p;
  p.sigma_ttc = 1e-9;  // p underflows to 0: tau_need = 4*2/(0 + 1e-6) = 8e6, finite
  s.distance_to_exit = 500.0;
  s.v = 20.0;
  s.target_lead = CavSituation::TargetLead{10.0, 10.0, 5.0};  // p-ttc 0.5 s
  r = computeReward(s, p);
  EXPECT_EQ(r.p, 0.0);
  EXPECT_NEAR(r.tau_need, 8e6, 1e-3);
  EXPECT_TRUE(std::isfinite(r.total));
}

TEST(Reward, StableSigmoid) {
  EXPECT_EQ(palcas::stableSigmoid(0.0), 0.5);
  EXPECT_EQ(palcas::stableSigmoid(INF), 1.0);
  EXPECT_EQ(palcas::stableSigmoid(-INF), 0.0);
  EXPECT_EQ(palcas::stableSigmoid(-800.0), 0.0);  // exp(800) would overflow
  EXPECT_EQ(palcas::stableSigmoid(800.0), 1.0);
  EXPECT_NEAR(palcas::stableSigmoid(-1.0), 0.2689414, 1e-7);  // 1/(1 + e)
}

TEST(Reward, RejectsBadSituationsNamingTheKey) {
  CavSituation s = quiet();
  s.v = std::nan("");
  expectRejected(s, "v");
  s = quiet();
  s.lane = 6;
  expectRejected(s, "lane");
  s = quiet();
  s.lane = -1;
  expectRejected(s, "lane");
  s = quiet();
  s.num_lanes = 0;
  s.lane = 0;
  expectRejected(s, "num_lanes");
  s = quiet();
  s.length = -4.0;
  expectRejected(s, "length");
  s = quiet();
  s.distance_to_exit = std::nan("");
  expectRejected(s, "distance_to_exit");
  s = quiet();
  s.distance_to_exit = -INF;
  expectRejected(s, "distance_to_exit");
  s = quiet();
  s.lead = CavSituation::GapSpeed{INF, 10.0};
  expectRejected(s, "lead.gap");
  s = quiet();
  s.lateral.assign(5, {1.0, 0.0, 0.0});
  expectRejected(s, "lateral");
  s = quiet();
  s.lateral = {{1.0, std::nan(""), 0.0}};
  expectRejected(s, "lateral[0].v_lat_ego");
  s = quiet();
  s.target_lead = CavSituation::TargetLead{10.0, 5.0, std::nan("")};
  expectRejected(s, "target_lead.length");
  s = quiet();
  s.accel_lane = CavSituation::AccelLane{10.0, 200.0};
  expectRejected(s, "accel_lane");
  s = quiet();
  s.lane = 0;
  s.accel_lane = CavSituation::AccelLane{10.0, 0.0};
  expectRejected(s, "accel_lane.length");
  s = quiet();
  s.v_max = 0.0;
  expectRejected(s, "v_max");
}

TEST(RewardParams, NamesGetAndSet) {
  RewardParams p;
  EXPECT_EQ(palcas::getRewardParam(p, "sigma_ttc"), 0.1);
  palcas::setRewardParam(p, "lambda", 0.0);  // the ablation of the paper
  EXPECT_EQ(p.lambda, 0.0);
  for (const auto& name : palcas::rewardParamNames())
    EXPECT_NO_THROW(palcas::getRewardParam(RewardParams(), name)) << name;
}

TEST(RewardParams, UnknownNameListsValidNamesAndChangesNothing) {
  RewardParams p;
  const auto setLamda = [&] { palcas::setRewardParam(p, "lamda", 0.0); };
  palcas_test::expectThrowNaming<std::invalid_argument>(setLamda, "'lamda'");
  palcas_test::expectThrowNaming<std::invalid_argument>(setLamda, "lambda");
  EXPECT_EQ(p.lambda, 0.4);
}

TEST(RewardParams, ValidationNamesTheBadConstant) {
  const auto expectBad = [](const std::string& name, double value) {
    RewardParams p;
    palcas::setRewardParam(p, name, value);
    SCOPED_TRACE(testing::Message() << name << " = " << value);
    palcas_test::expectThrowNaming<std::invalid_argument>(
        [&] { palcas::validateRewardParams(p); }, name);
  };
  expectBad("epsilon", 0.0);
  expectBad("sigma_ttc", 0.0);
  expectBad("v_max_ego", 0.0);  // v_max - v_min = 0
  expectBad("a_min", -2.6);     // |a_min| - a_max = 0
  expectBad("beta", -1.0);
  expectBad("zeta", std::nan(""));
  expectBad("a_b_lat", 0.0);
  EXPECT_NO_THROW(palcas::validateRewardParams(RewardParams()));
}

// config/reward.yaml must document every constant, with the paper's default value.
TEST(RewardParams, YamlListsEveryConstantWithItsDefault) {
  std::ifstream in(PALCAS_REWARD_YAML);
  ASSERT_TRUE(in) << "cannot open " << PALCAS_REWARD_YAML;
  const std::regex entry(R"(^  ([a-z_0-9]+):\s*([-+0-9.eE]+)\s*(#.*)?$)");
  std::map<std::string, double> values;
  std::string line;
  bool in_reward = false;
  while (std::getline(in, line)) {
    if (line.rfind("reward:", 0) == 0) in_reward = true;
    std::smatch m;
    if (in_reward && std::regex_match(line, m, entry)) values[m[1]] = std::stod(m[2]);
  }
  const RewardParams defaults;
  for (const auto& name : palcas::rewardParamNames()) {
    ASSERT_TRUE(values.count(name)) << "reward.yaml lacks " << name;
    EXPECT_EQ(values[name], palcas::getRewardParam(defaults, name)) << name;
  }
  EXPECT_EQ(values.size(), palcas::rewardParamNames().size());
}

namespace {

palcas::VehicleSnapshot vehicle(const std::string& id, int lane, double x, double lateral) {
  palcas::VehicleSnapshot v;
  v.id = id;
  v.lane = lane;
  v.x_m = x;
  v.lateral_m = lateral;
  v.speed_mps = 20.0;
  v.length_m = 5.0;
  v.width_m = 1.8;
  v.distance_to_exit_m = INF;
  return v;
}

}  // namespace

TEST(CavSituation, BuiltFromASnapshot) {
  palcas::VehicleSnapshot ego = vehicle("ego", 3, 100.0, 8.0);
  ego.lateral_speed_mps = -0.5;  // drifting right
  ego.distance_to_exit_m = 700.0;
  ego.max_speed_mps = 30.0;
  palcas::VehicleSnapshot right_lead = vehicle("rl", 2, 120.0, 4.8);
  right_lead.length_m = 4.0;
  right_lead.speed_mps = 18.0;
  palcas::VehicleSnapshot left_follow = vehicle("lf", 4, 90.0, 11.2);
  left_follow.lateral_speed_mps = -0.3;  // drifting right, toward the ego
  const palcas::RoadSnapshot snap{
      5,
      {ego, right_lead, left_follow, vehicle("own", 3, 150.0, 8.0), vehicle("rf", 2, 70.0, 4.8)}};
  const palcas::NeighbourFinder finder(snap);
  const CavSituation s =
      palcas::situationFromSnapshot(finder, "ego", palcas::ClusterStats{22.0, {}});
  EXPECT_EQ(s.lane, 3);
  EXPECT_EQ(s.num_lanes, 5);
  EXPECT_EQ(s.distance_to_exit, 700.0);
  ASSERT_TRUE(s.v_max.has_value());
  EXPECT_EQ(*s.v_max, 30.0);
  EXPECT_EQ(s.cluster_mean_speed, 22.0);
  ASSERT_TRUE(s.lead.has_value());
  EXPECT_DOUBLE_EQ(s.lead->gap, 45.0);  // 150 - 5 - 100
  EXPECT_FALSE(s.follow.has_value());
  // Target lane = lane 2: lead front-to-front 120 - 100 = 20 m, follower 100 - 70 = 30 m.
  ASSERT_TRUE(s.target_lead.has_value());
  EXPECT_DOUBLE_EQ(s.target_lead->distance, 20.0);
  EXPECT_DOUBLE_EQ(s.target_lead->length, 4.0);
  EXPECT_DOUBLE_EQ(s.target_lead->v, 18.0);
  ASSERT_TRUE(s.target_follow.has_value());
  EXPECT_DOUBLE_EQ(s.target_follow->distance, 30.0);
  // Lateral: left follower first (slot order), then right lead, right follower.
  ASSERT_EQ(s.lateral.size(), 3u);
  // left follower: |11.2 - 8.0| - (1.8 + 1.8)/2 = 3.2 - 1.8 = 1.4; toward it = +left:
  // v_lat_ego = -0.5 (moving away), v_lat_other = -0.3 (moving toward the ego)
  EXPECT_NEAR(s.lateral[0].gap, 1.4, 1e-12);
  EXPECT_DOUBLE_EQ(s.lateral[0].v_lat_ego, -0.5);
  EXPECT_DOUBLE_EQ(s.lateral[0].v_lat_other, -0.3);
  // right lead: toward it = -left, so v_lat_ego = +0.5 (closing), v_lat_other = -0
  EXPECT_NEAR(s.lateral[1].gap, 1.4, 1e-12);
  EXPECT_DOUBLE_EQ(s.lateral[1].v_lat_ego, 0.5);
  EXPECT_NO_THROW(computeReward(s, RewardParams()));
  EXPECT_THROW(palcas::situationFromSnapshot(finder, "nobody", {}), std::invalid_argument);
}

TEST(CavSituation, AccelerationLaneTargetsLaneOne) {
  palcas::VehicleSnapshot ego = vehicle("ego", 0, 300.0, -1.6);
  ego.on_accel_lane = true;
  ego.accel_lane_pos_m = 120.0;
  ego.accel_lane_length_m = 250.0;
  const palcas::RoadSnapshot snap{5,
                                  {ego, vehicle("m", 1, 310.0, 1.6), vehicle("m2", 2, 305.0, 4.8)}};
  const CavSituation s =
      palcas::situationFromSnapshot(palcas::NeighbourFinder(snap), "ego", palcas::ClusterStats{});
  ASSERT_TRUE(s.accel_lane.has_value());
  EXPECT_EQ(s.accel_lane->x, 120.0);
  EXPECT_EQ(s.accel_lane->length, 250.0);
  ASSERT_TRUE(s.target_lead.has_value());
  EXPECT_DOUBLE_EQ(s.target_lead->distance, 10.0);  // lane 1 vehicle: 310 - 300
  EXPECT_FALSE(s.target_follow.has_value());
  EXPECT_EQ(s.lateral.size(), 1u);  // only lane 1 is adjacent; lane 2 is not
}

TEST(CavSituation, ExitLaneHasNoTargetLane) {
  const palcas::RoadSnapshot snap{5, {vehicle("ego", 1, 300.0, 1.6), vehicle("m", 2, 310.0, 4.8)}};
  const CavSituation s =
      palcas::situationFromSnapshot(palcas::NeighbourFinder(snap), "ego", palcas::ClusterStats{});
  EXPECT_FALSE(s.target_lead.has_value());
  EXPECT_FALSE(s.target_follow.has_value());
  EXPECT_EQ(s.lateral.size(), 1u);
}

// ---- Departures from the printed paper (config/departures.yaml); each off = the paper ----

TEST(RewardDepartures, DefaultsAreThePapersFormulas) {
  const RewardParams p;
  EXPECT_EQ(p.lateral_rss_overlap_only, 0.0);
  EXPECT_EQ(p.lateral_rss_signed, 0.0);
  EXPECT_EQ(p.comfort_penalty_only, 0.0);
  EXPECT_EQ(p.tte_speed_floor_mps, 0.0);
}

TEST(RewardDepartures, LateralRssCanCountOnlyNeighboursAlongside) {
  CavSituation s = quiet();
  // Gap 0.07 < delta 0.14 -> -0.5 each; the first is 40 m ahead, the second alongside.
  s.lateral = {{0.07, 0.0, 0.0, 40.0}, {0.07, 0.0, 0.0, -2.0}};
  EXPECT_NEAR(computeReward(s, RewardParams()).r_s_lat, -1.0, 1e-12);  // paper: both
  RewardParams p;
  p.lateral_rss_overlap_only = 1.0;
  EXPECT_NEAR(computeReward(s, p).r_s_lat, -0.5, 1e-12);
}

TEST(RewardDepartures, SignedLateralRssDoesNotPayForMovingAway) {
  CavSituation s = quiet();
  // Ego moving away from the neighbour at 3 m/s (frame: + = toward it).
  s.lateral = {{1.0, -3.0, 0.0}};
  // Paper: v_i,rho = -2.8: ego part 0.5(-3 - 2.8)0.2 + 2.8^2/2 = -0.58 + 3.92 = 3.34;
  // other part 0.5(0 + 0.2)0.2 - 0.02 = 0; delta = 0.1 + 3.34 = 3.44 > gap 1 -> penalty.
  const auto paper = computeReward(s, RewardParams());
  EXPECT_NEAR(paper.delta_lat[0], 3.44, 1e-9);
  EXPECT_LT(paper.r_s_lat, 0.0);
  RewardParams p;
  p.lateral_rss_signed = 1.0;  // ego part -0.58 - 3.92 < 0 -> delta = mu = 0.1
  const auto ours = computeReward(s, p);
  EXPECT_NEAR(ours.delta_lat[0], 0.1, 1e-9);
  EXPECT_EQ(ours.r_s_lat, 0.0);
  // Toward the neighbour both agree.
  s.lateral = {{1.0, 3.0, 0.0}};
  EXPECT_NEAR(computeReward(s, p).delta_lat[0], computeReward(s, RewardParams()).delta_lat[0], 1e-12);
}

TEST(RewardDepartures, ComfortPenaltyOnlyGivesNoBonusForStandingStill) {
  CavSituation s = quiet();
  s.v = 0.0;
  s.cluster_mean_speed = 0.0;
  EXPECT_NEAR(computeReward(s, RewardParams()).r_c, 0.7736842, 1e-6);  // paper: a bonus
  RewardParams p;
  p.comfort_penalty_only = 1.0;
  EXPECT_EQ(computeReward(s, p).r_c, 0.0);
  s.a = -3.0;  // discomfort is still paid
  EXPECT_NEAR(computeReward(s, p).r_c, -0.8052632, 1e-6);
}

TEST(RewardDepartures, SpeedFloorKeepsTheUrgencyOfAStoppedCar) {
  CavSituation s = quiet();
  s.lane = 5;
  s.v = 0.0;
  s.distance_to_exit = 300.0;  // beyond d_th: the sigmoid branch
  const auto paper = computeReward(s, RewardParams());
  EXPECT_GT(paper.tau_tte, 1e8);       // 300 / 1e-6
  EXPECT_NEAR(paper.u, 0.0, 1e-12);    // stopping removed the urgency
  RewardParams p;
  p.tte_speed_floor_mps = 10.0;
  const auto ours = computeReward(s, p);
  EXPECT_NEAR(ours.tau_tte, 30.0, 1e-9);  // 300 / 10; tau_need = 4 x 2 = 8
  EXPECT_NEAR(ours.u, -1.0 / (1.0 + std::exp(30.0 - 8.0 / (1.0 + 1e-6))), 1e-9);
  EXPECT_LT(ours.r_lc, paper.r_lc);
}

TEST(RewardDepartures, FlagsMustBeZeroOrOne) {
  RewardParams p;
  p.lateral_rss_signed = 0.5;
  EXPECT_THROW(palcas::validateRewardParams(p), std::invalid_argument);
  p = RewardParams();
  p.tte_speed_floor_mps = -1.0;
  EXPECT_THROW(palcas::validateRewardParams(p), std::invalid_argument);
}
