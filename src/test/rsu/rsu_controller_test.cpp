#include "palcas_core/rsu/rsu_controller.h"

#include <gtest/gtest.h>

#include "common/throws_naming.h"
#include "learning/checkpoint_without_masks.h"

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "palcas_core/common/rng.h"
#include "palcas_core/state/neighbours.h"
#include "palcas_core/state/state_layout.h"

using palcas::Action;
using palcas::ActionMask;
using palcas::ALL_ACTIONS;
using palcas::Decision;
using palcas::GlobalDensities;
using palcas::ModelBlob;
using palcas::PdqnAgent;
using palcas::ReplayBatch;
using palcas::RoadSnapshot;
using palcas::StateBuilder;
using palcas::VehicleSnapshot;
using palcas::nn::Index;
using palcas::nn::Matrix;
using palcas::rsu::computeClusterSummary;
using palcas::rsu::DecisionOutput;
using palcas::rsu::RsuController;
using palcas::rsu::RsuControllerOptions;
using palcas::rsu::VehicleOutcomes;

namespace {

constexpr double INF = std::numeric_limits<double>::infinity();
constexpr double NaN = std::numeric_limits<double>::quiet_NaN();
constexpr double V_LIMIT = 33.528;

// Hand-computed rewards of a lone CAV in lane 1 without an exit (paper "Reward Function",
// defaults iota .05 zeta .5 xi .05 lambda .4 psi .1, w_c = w_e = .5, own v_max 33.528):
// no neighbours -> r_s = 0; lane 1, no exit -> n = 0, u w = 0, p_stage = -2 (1 - .5)(1 - 0)
// = -1 -> r_lc = -1; not on the acceleration lane -> r_d = 0.
// R_SLOW: v = 20, a = 1, cluster mean 20: r_e = -(33.528 - 20) / 33.528 = -0.40348366;
//   r_c = (1.47 - 1) / 1.9 = 0.24736842;
//   total = .05 (-0.40348366) + .05 (0.24736842) + .4 (-1) = -0.40780576
constexpr double R_SLOW = -0.40780576;
// R_FAST: v = 33.528, a = 0, cluster mean 33.528: r_e = 0; r_c = 1.47 / 1.9 = 0.77368421;
//   total = .05 (0.77368421) - .4 = -0.36131579
constexpr double R_FAST = -0.36131579;
// Lane 5 (n = 4 = L - 1), no exit, v = 33.528, a = 0: u w = 0; p_stage = -2 (.5)(1 - 4/4) = 0
//   -> total = .05 (0.77368421) = 0.03868421
constexpr double R_FAST_LANE5 = 0.03868421;

RsuControllerOptions smallOptions(bool train = true) {
  RsuControllerOptions o;
  o.rsu_id = "rsu_1";
  o.cluster_index = 1;
  o.x_start_m = 800.0;
  o.x_end_m = 1600.0;
  o.train = train;
  o.pdqn.hidden_sizes = {16, 16};
  o.pdqn.batch_size = 8;
  o.pdqn.replay_capacity = 256;
  o.pdqn.seed = 7;
  return o;
}

VehicleSnapshot cav(const std::string& id, int lane, double x, double v = V_LIMIT,
                    double a = 0.0) {
  VehicleSnapshot s;
  s.id = id;
  s.is_cav = true;
  s.lane = lane;
  s.x_m = x;
  s.lateral_m = 3.2 * (lane - 0.5);
  s.speed_mps = v;
  s.accel_mps2 = a;
  s.distance_to_exit_m = INF;
  return s;
}

// A CAV on the acceleration lane (lane 0), 100 m along its 250 m.
VehicleSnapshot mergingCav(const std::string& id, double x, double v = V_LIMIT, double a = 0.0) {
  VehicleSnapshot s = cav(id, 0, x, v, a);
  s.on_accel_lane = true;
  s.lateral_m = -1.6;
  s.accel_lane_pos_m = 100.0;
  s.accel_lane_length_m = 250.0;
  return s;
}

RoadSnapshot road(std::vector<VehicleSnapshot> vehicles) {
  RoadSnapshot r;
  r.num_lanes = 5;
  r.vehicles = std::move(vehicles);
  return r;
}

// Eight CAVs spread over the zone, moved 10 m per call so states change.
RoadSnapshot eightCavs(int call) {
  std::vector<VehicleSnapshot> v;
  for (int i = 0; i < 8; ++i)
    v.push_back(cav("c" + std::to_string(i), 1 + i % 5, 850.0 + 80.0 * i + 10.0 * call, 25.0));
  return road(v);
}

const GlobalDensities GLOBAL{10.0, 20.0, NaN};
constexpr ActionMask NO_LEFT = ALL_ACTIONS & ~palcas::actionBit(Action::kLaneLeft);
constexpr ActionMask NO_RIGHT = ALL_ACTIONS & ~palcas::actionBit(Action::kLaneRight);

// The agent's decode of the TD target's mask before the masks were stored with the
// transitions (test-only copy): the lane of s' from its ego-lane feature lane / L.
void oldMaskInvalidNextActions(const Matrix& next_states, int lanes, Matrix& q) {
  const Index lane_row = static_cast<Index>(palcas::EgoFeature::kLane);
  constexpr float BLOCKED = -std::numeric_limits<float>::infinity();
  for (Index j = 0; j < next_states.cols(); ++j) {
    const int lane = static_cast<int>(std::lround(next_states(lane_row, j) * lanes));
    if (lane >= lanes) q(static_cast<Index>(Action::kLaneLeft), j) = BLOCKED;
    if (lane <= 1) q(static_cast<Index>(Action::kLaneRight), j) = BLOCKED;
  }
}

// The actions the old decode left in s'.
ActionMask oldDecodedMask(const palcas::nn::Vector& next_state, int lanes) {
  Matrix q = Matrix::Zero(palcas::ACTION_COUNT, 1);
  oldMaskInvalidNextActions(next_state, lanes, q);
  ActionMask mask = 0;
  for (Index a = 0; a < palcas::ACTION_COUNT; ++a)
    if (std::isfinite(q(a, 0))) mask |= palcas::actionBit(static_cast<Action>(a));
  return mask;
}
const VehicleOutcomes NONE{};

// The only stored transition (replay of size 1: every sample is index 0).
ReplayBatch onlyTransition(const RsuController& c) {
  EXPECT_EQ(c.agent().replay().size(), 1u);
  palcas::Rng rng(1);
  ReplayBatch batch;
  c.agent().replay().sample(1, rng, batch);
  return batch;
}

// The state the controller should build for `id` of `snapshot` (own cluster statistics).
palcas::nn::Vector stateOf(const RsuControllerOptions& o, const RoadSnapshot& snapshot,
                           const std::string& id) {
  const auto cluster = computeClusterSummary(snapshot, o.x_start_m, o.x_end_m, V_LIMIT);
  return StateBuilder(o.num_lanes, o.scales)
      .buildStates(snapshot, {id}, cluster.toClusterStats(), GLOBAL)
      .col(0);
}

double rewardOf(const RsuControllerOptions& o, const RoadSnapshot& snapshot,
                const std::string& id) {
  const auto cluster = computeClusterSummary(snapshot, o.x_start_m, o.x_end_m, V_LIMIT);
  const palcas::NeighbourFinder finder(snapshot);
  return palcas::computeReward(
             palcas::situationFromSnapshot(finder, id, cluster.toClusterStats()), o.reward)
      .total;
}

void expectSameDecisions(const DecisionOutput& a, const DecisionOutput& b) {
  ASSERT_EQ(a.advisories.size(), b.advisories.size());
  for (size_t i = 0; i < a.advisories.size(); ++i) {
    EXPECT_EQ(a.advisories[i].vehicle_id, b.advisories[i].vehicle_id);
    EXPECT_EQ(a.advisories[i].decision.action, b.advisories[i].decision.action);
    EXPECT_EQ(a.advisories[i].decision.accel_mps2, b.advisories[i].decision.accel_mps2);
  }
}

template <typename F>
void expectInvalid(F&& f, const std::string& needle) {
  palcas_test::expectThrowNaming<std::invalid_argument>(f, needle);
}

}  // namespace

TEST(RsuControllerOptions, RejectsBadFieldsNamingThem) {
  auto bad = [](auto change, const std::string& field) {
    RsuControllerOptions o = smallOptions();
    change(o);
    expectInvalid([&] { o.validate(); }, field);
    expectInvalid([&] { RsuController c(o); }, field);
  };
  bad([](auto& o) { o.rsu_id = ""; }, "rsu_id");
  bad([](auto& o) { o.cluster_index = -1; }, "cluster_index");
  bad([](auto& o) { o.x_start_m = NaN; }, "x_start_m");
  bad([](auto& o) { o.x_end_m = 800.0; }, "x_end_m");
  bad([](auto& o) { o.num_lanes = 0; }, "num_lanes");
  bad([](auto& o) { o.gradient_steps_per_decision = -0.5; }, "gradient_steps_per_decision");
  bad([](auto& o) { o.terminal.collision_penalty = NaN; }, "collision_penalty");
  bad([](auto& o) { o.terminal.collision_penalty = -1.0; }, "collision_penalty");
  bad([](auto& o) { o.terminal.exit_taken_bonus = -1.0; }, "exit_taken_bonus");
  bad([](auto& o) { o.terminal.exit_taken_bonus = NaN; }, "exit_taken_bonus");
  bad([](auto& o) { o.terminal.exit_missed_penalty = -1.0; }, "exit_missed_penalty");
  bad([](auto& o) { o.terminal.merge_failed_penalty = NaN; }, "merge_failed_penalty");
  bad([](auto& o) { o.num_lanes = 4; }, "pdqn.state_size");  // 40 + 4 = 44 != 45
  bad([](auto& o) { o.reward.rho = NaN; }, "reward");
  bad([](auto& o) { o.scales.speed_mps = 0.0; }, "scales");
  bad([](auto& o) { o.pdqn.batch_size = 0; }, "pdqn");
  EXPECT_NO_THROW(smallOptions().validate());
}

TEST(VehicleOutcomes, AddFilesEventsByKind) {
  using K = palcas::metrics::VehicleEventKind;
  VehicleOutcomes o;
  o.add(K::kCollision, "a");
  o.add(K::kTeleport, "b");
  o.add(K::kArrived, "c");
  o.add(K::kExitOk, "d");
  o.add(K::kExitMissed, "e");
  o.add(K::kDeparted, "f");
  o.add(K::kMergeOk, "g");
  o.add(K::kMergeFailed, "h");
  EXPECT_EQ(o.collided, std::vector<std::string>{"a"});
  EXPECT_EQ(o.teleported, std::vector<std::string>{"b"});
  EXPECT_EQ(o.arrived, std::vector<std::string>{"c"});
  EXPECT_EQ(o.exited, std::vector<std::string>{"d"});
  EXPECT_EQ(o.exit_missed, std::vector<std::string>{"e"});
  o.clear();
  EXPECT_TRUE(o.collided.empty() && o.exit_missed.empty());
}

TEST(RsuController, MembersAreCavsInTheZoneOnMainlineOrAccelerationLane) {
  RsuController c(smallOptions());
  const VehicleSnapshot merging = mergingCav("merging", 1000.0);
  VehicleSnapshot ramp = cav("ramp", 0, 1100.0);  // on-ramp before its acceleration lane
  ramp.lateral_m = -5.0;
  VehicleSnapshot hdv = cav("hdv", 2, 1000.0);
  hdv.is_cav = false;
  VehicleSnapshot handed_back = cav("handed_back", 2, 1200.0);  // its zone is busy: not advised
  handed_back.driving_itself = true;
  const RoadSnapshot r = road({cav("start", 1, 800.0), cav("end", 3, 1599.9),
                               cav("past", 2, 1600.0), cav("before", 4, 799.9), merging, ramp,
                               hdv, handed_back});
  const DecisionOutput out = c.decide(r, 1, 0.1, GLOBAL, NONE);
  ASSERT_EQ(out.advisories.size(), 3u);  // one per member, in snapshot order
  EXPECT_EQ(out.advisories[0].vehicle_id, "start");
  EXPECT_EQ(out.advisories[1].vehicle_id, "end");
  EXPECT_EQ(out.advisories[2].vehicle_id, "merging");
  EXPECT_EQ(c.stats().member_count, 3u);
  EXPECT_EQ(c.pendingCount(), 3u);
  EXPECT_FALSE(c.isMember(hdv));
  EXPECT_FALSE(c.isMember(ramp));
  EXPECT_FALSE(c.isMember(handed_back));
}

TEST(RsuController, DecidesForAllMembersInOneGreedyBatchInEvalMode) {
  const RsuControllerOptions o = smallOptions(false);
  RsuController c(o);
  const RoadSnapshot r = eightCavs(0);
  const DecisionOutput out = c.decide(r, 3, 0.3, GLOBAL, NONE);
  EXPECT_EQ(c.agent().decisionRounds(), 1u);  // ONE act() for all eight
  // Same decisions as a fresh agent of the same seed acting greedily on the states.
  std::vector<std::string> ids;
  for (const auto& v : r.vehicles) ids.push_back(v.id);
  const auto cluster = computeClusterSummary(r, o.x_start_m, o.x_end_m, V_LIMIT);
  const auto states =
      StateBuilder(5, o.scales).buildStates(r, ids, cluster.toClusterStats(), GLOBAL);
  PdqnAgent agent(o.pdqn);
  const std::vector<Decision> expected = agent.act(states, false);
  ASSERT_EQ(out.advisories.size(), 8u);
  uint32_t counted = 0;
  for (size_t i = 0; i < 8; ++i) {
    EXPECT_EQ(out.advisories[i].vehicle_id, ids[i]);
    EXPECT_EQ(out.advisories[i].decision.action, expected[i].action);
    EXPECT_EQ(out.advisories[i].decision.accel_mps2, expected[i].accel_mps2);
  }
  for (uint32_t n : c.stats().action_counts) counted += n;
  EXPECT_EQ(counted, 8u);
  EXPECT_EQ(out.step, 3u);
  EXPECT_DOUBLE_EQ(out.time_s, 0.3);
}

TEST(RsuController, PublishesTheZoneStatistics) {
  RsuController c(smallOptions());
  VehicleSnapshot hdv = cav("hdv", 2, 1000.0, 10.0);
  hdv.is_cav = false;
  const DecisionOutput out =
      c.decide(road({cav("a", 1, 900.0, 20.0), hdv, cav("out", 1, 1700.0, 5.0)}), 1, 0.1,
               GLOBAL, NONE);
  // counted: a (20 m/s, lane 1) and hdv (10 m/s, lane 2); mean = (20 + 10) / 2 = 15 m/s
  EXPECT_DOUBLE_EQ(out.cluster.mean_speed_mps, 15.0);
  // 1 vehicle / 0.8 km = 1.25 veh/km in lanes 1 and 2; total 2 / 0.8 = 2.5 veh/km
  EXPECT_DOUBLE_EQ(out.cluster.lane_density_veh_per_km[0], 1.25);
  EXPECT_DOUBLE_EQ(out.cluster.lane_density_veh_per_km[1], 1.25);
  EXPECT_DOUBLE_EQ(out.cluster.lane_density_veh_per_km[2], 0.0);
  EXPECT_DOUBLE_EQ(out.cluster.density_veh_per_km, 2.5);
  EXPECT_EQ(out.cluster.vehicle_count, 2u);
  EXPECT_EQ(out.cluster.cav_count, 1u);
}

TEST(RsuController, ContinuingCavStoresTheRewardOfItsSituationNow) {
  const RsuControllerOptions o = smallOptions();
  RsuController c(o);
  const DecisionOutput first =
      c.decide(road({cav("a", 1, 900.0, 20.0, 1.0)}), 1, 0.1, GLOBAL, NONE);
  EXPECT_EQ(c.agent().replay().size(), 0u);  // nothing to close yet
  const RoadSnapshot now = road({cav("a", 1, 920.0)});
  c.decide(now, 2, 0.2, GLOBAL, NONE);
  const ReplayBatch t = onlyTransition(c);
  EXPECT_NEAR(t.rewards(0), R_FAST, 1e-6);
  EXPECT_NEAR(t.rewards(0), rewardOf(o, now, "a"), 1e-6);
  EXPECT_EQ(t.dones(0), 0.0f);
  EXPECT_EQ(t.actions[0], static_cast<int>(first.advisories[0].decision.action));
  EXPECT_TRUE(t.next_states.col(0).isApprox(stateOf(o, now, "a")));
  EXPECT_EQ(c.samplesSinceFederation(), 1u);
  EXPECT_NEAR(c.stats().sum_reward, R_FAST, 1e-6);
}

TEST(RsuController, HandedOverCavContinuesWithItsStateNow) {
  const RsuControllerOptions o = smallOptions();
  RsuController c(o);
  c.decide(road({cav("a", 1, 1590.0, 20.0, 1.0)}), 1, 0.1, GLOBAL, NONE);
  const RoadSnapshot now = road({cav("a", 1, 1605.0)});  // in the next RSU's zone
  const DecisionOutput out = c.decide(now, 2, 0.2, GLOBAL, NONE);
  EXPECT_TRUE(out.advisories.empty());
  EXPECT_EQ(c.pendingCount(), 0u);
  const ReplayBatch t = onlyTransition(c);
  EXPECT_EQ(t.dones(0), 0.0f);  // the value continues under the next RSU (shared model)
  // Zone now empty: its mean speed is the free-flow 33.528 -> R_FAST.
  EXPECT_NEAR(t.rewards(0), R_FAST, 1e-6);
  EXPECT_TRUE(t.next_states.col(0).isApprox(stateOf(o, now, "a")));
}

TEST(RsuController, CollidedCavIsTerminalWithThePenalty) {
  for (const bool teleport : {false, true}) {
    RsuControllerOptions o = smallOptions();
    o.terminal.collision_penalty = 2.0;
    RsuController c(o);
    const RoadSnapshot before = road({cav("a", 1, 900.0, 20.0, 1.0), cav("b", 3, 1000.0)});
    c.decide(before, 1, 0.1, GLOBAL, NONE);
    VehicleOutcomes events;
    (teleport ? events.teleported : events.collided).push_back("a");
    c.decide(road({cav("b", 3, 1030.0)}), 2, 0.2, GLOBAL, events);
    ASSERT_EQ(c.agent().replay().size(), 2u);  // closed in id order: a, then b
    // reward at its last observation minus the penalty 2
    // (b was in the zone too, so the cluster mean was (20 + 33.528) / 2: use computeReward)
    EXPECT_NEAR(c.agent().replay().rewardAt(0), rewardOf(o, before, "a") - 2.0, 1e-6);
    palcas::Rng rng(3);
    ReplayBatch batch;
    c.agent().replay().sample(16, rng, batch);
    for (int i = 0; i < 16; ++i) {
      const bool is_a = batch.rewards(i) < -2.0f;
      EXPECT_EQ(batch.dones(i), is_a ? 1.0f : 0.0f);
      if (is_a) {
        EXPECT_TRUE(batch.next_states.col(i).isApprox(batch.states.col(i)));  // s' = s
      }
    }
  }
}

TEST(RsuController, CollidedCavStillInTheSnapshotIsNotAdvised) {
  RsuController c(smallOptions());
  c.decide(road({cav("a", 1, 900.0, 20.0, 1.0)}), 1, 0.1, GLOBAL, NONE);
  VehicleOutcomes events;
  events.collided = {"a"};
  const DecisionOutput out = c.decide(road({cav("a", 1, 905.0)}), 2, 0.2, GLOBAL, events);
  EXPECT_TRUE(out.advisories.empty());
  EXPECT_EQ(onlyTransition(c).dones(0), 1.0f);
  // lone CAV at 20 m/s, a = 1: R_SLOW, no penalty by default (the paper defines none)
  EXPECT_NEAR(onlyTransition(c).rewards(0), R_SLOW, 1e-6);
}

TEST(RsuController, ExitArrivalAndDisappearanceAreTerminalWithoutPenalty) {
  for (int kind = 0; kind < 3; ++kind) {
    RsuControllerOptions o = smallOptions();
    o.terminal.collision_penalty = 5.0;  // must not apply
    RsuController c(o);
    c.decide(road({cav("a", 1, 900.0, 20.0, 1.0)}), 1, 0.1, GLOBAL, NONE);
    VehicleOutcomes events;
    if (kind == 0) events.exited = {"a"};
    if (kind == 1) events.arrived = {"a"};  // kind 2: simply gone from the snapshot
    c.decide(road({}), 2, 0.2, GLOBAL, events);
    // Gone without an event: its event may still be on its way; closed one decision later.
    if (kind == 2) {
      EXPECT_EQ(c.agent().replay().size(), 0u);
      c.decide(road({}), 3, 0.3, GLOBAL, NONE);
    }
    const ReplayBatch t = onlyTransition(c);
    EXPECT_EQ(t.dones(0), 1.0f) << kind;
    EXPECT_NEAR(t.rewards(0), R_SLOW, 1e-6) << kind;  // the reward at its last observation
    EXPECT_TRUE(t.next_states.col(0).isApprox(t.states.col(0))) << kind;
  }
}

TEST(RsuController, VanishedCavGetsTheCollisionPenaltyOfALateEvent) {
  RsuControllerOptions o = smallOptions();
  o.terminal.collision_penalty = 5.0;
  RsuController c(o);
  c.decide(road({cav("a", 1, 900.0, 20.0, 1.0)}), 1, 0.1, GLOBAL, NONE);
  c.decide(road({}), 2, 0.2, GLOBAL, NONE);  // gone; its COLLISION event comes later
  VehicleOutcomes late;
  late.collided = {"a"};
  c.decide(road({}), 3, 0.3, GLOBAL, late);
  const ReplayBatch t = onlyTransition(c);
  EXPECT_EQ(t.dones(0), 1.0f);
  EXPECT_NEAR(t.rewards(0), R_SLOW - 5.0, 1e-6);
}

TEST(RsuController, CavOnItsOffRampIsTheExitTakenWithoutWaitingForTheEvent) {
  for (double bonus : {0.0, 2.0}) {
    RsuControllerOptions o = smallOptions();
    o.terminal.exit_taken_bonus = bonus;
    RsuController c(o);
    c.decide(road({cav("a", 1, 900.0, 20.0, 1.0)}), 1, 0.1, GLOBAL, NONE);
    VehicleSnapshot off = cav("a", 0, 930.0, 15.0);
    off.lateral_m = -3.0;
    c.decide(road({off}), 2, 0.2, GLOBAL, NONE);  // EXIT_OK not received yet
    const ReplayBatch t = onlyTransition(c);
    EXPECT_EQ(t.dones(0), 1.0f);
    // The reward of its last mainline observation (the off-ramp's own situation says
    // nothing about the decision) plus the bonus.
    EXPECT_NEAR(t.rewards(0), R_SLOW + bonus, 1e-6);
  }
}

TEST(RsuController, PassingTheExitIsPenalisedAndTerminalWhenAsked) {
  for (bool ours : {false, true}) {
    RsuControllerOptions o = smallOptions();
    if (ours) {
      o.terminal.exit_missed_penalty = 10.0;
      o.terminal.exit_missed_terminal = true;
    }
    RsuController c(o);
    VehicleSnapshot before = cav("a", 3, 900.0);
    before.distance_to_exit_m = 20.0;
    c.decide(road({before}), 1, 0.1, GLOBAL, NONE);
    const RoadSnapshot after = road({cav("a", 3, 933.5)});  // past its off-ramp: d = +inf
    c.decide(after, 2, 0.2, GLOBAL, NONE);               // no EXIT_MISSED event needed
    const ReplayBatch t = onlyTransition(c);
    EXPECT_EQ(t.dones(0), ours ? 1.0f : 0.0f);
    EXPECT_NEAR(t.rewards(0), rewardOf(o, after, "a") - (ours ? 10.0 : 0.0), 1e-6);
  }
}

TEST(RsuController, FailedMergeIsPenalised) {
  RsuControllerOptions o = smallOptions();
  o.terminal.merge_failed_penalty = 5.0;
  RsuController c(o);
  c.decide(road({cav("a", 1, 900.0)}), 1, 0.1, GLOBAL, NONE);
  VehicleOutcomes events;
  events.merge_failed = {"a"};
  c.decide(road({cav("a", 1, 900.0)}), 2, 0.2, GLOBAL, events);
  EXPECT_NEAR(onlyTransition(c).rewards(0), R_FAST - 5.0, 1e-6);
}

TEST(RsuController, RewardOverThePeriodIsTheMeanOfItsSteps) {
  for (bool over_period : {false, true}) {
    RsuControllerOptions o = smallOptions();
    o.reward_over_period = over_period;
    RsuController c(o);
    c.decide(road({cav("a", 1, 900.0)}), 10, 1.0, GLOBAL, NONE);
    c.observeStep(road({cav("a", 1, 902.0, 20.0, 1.0)}));  // two steps between: slow, fast
    c.observeStep(road({cav("a", 1, 904.0)}));
    c.decide(road({cav("a", 1, 906.0)}), 20, 2.0, GLOBAL, NONE);
    const double expected = over_period ? (R_SLOW + R_FAST + R_FAST) / 3.0 : R_FAST;
    EXPECT_NEAR(onlyTransition(c).rewards(0), expected, 1e-6) << over_period;
  }
}

TEST(RsuController, MissedExitAndUnknownIdsChangeNothing) {
  RsuController c(smallOptions());
  c.decide(road({cav("a", 1, 900.0, 20.0, 1.0)}), 1, 0.1, GLOBAL, NONE);
  VehicleOutcomes events;
  events.exit_missed = {"a"};
  events.collided = {"ghost"};
  events.arrived = {"nobody"};
  const DecisionOutput out = c.decide(road({cav("a", 1, 920.0)}), 2, 0.2, GLOBAL, events);
  EXPECT_EQ(out.advisories.size(), 1u);
  const ReplayBatch t = onlyTransition(c);
  EXPECT_EQ(t.dones(0), 0.0f);
  EXPECT_NEAR(t.rewards(0), R_FAST, 1e-6);
}

TEST(RsuController, StatsSumTheRewardsOfTheClosedTransitions) {
  RsuController c(smallOptions());
  const RoadSnapshot r = road({cav("a", 1, 900.0), cav("b", 5, 1500.0)});
  c.decide(r, 1, 0.1, GLOBAL, NONE);
  c.decide(r, 2, 0.2, GLOBAL, NONE);
  const auto s = c.stats();
  EXPECT_EQ(s.transitions_closed, 2u);
  // R_k = R_FAST + R_FAST_LANE5 = -0.36131579 + 0.03868421 = -0.32263158; mean / 2
  EXPECT_NEAR(s.sum_reward, -0.32263158, 1e-6);
  EXPECT_NEAR(s.mean_reward, -0.16131579, 1e-6);
  EXPECT_EQ(s.transitions_stored, 2u);
  EXPECT_EQ(s.decisions, 2u);
  EXPECT_LT(s.epsilon, 1.0);  // decayed by the two exploring rounds
}

TEST(RsuController, EvalModeIsDeterministicAndDoesNotLearn) {
  RsuController a(smallOptions(false)), b(smallOptions(false));
  for (int call = 0; call < 3; ++call) {
    const DecisionOutput da = a.decide(eightCavs(call), call, 0.1 * call, GLOBAL, NONE);
    const DecisionOutput db = b.decide(eightCavs(call), call, 0.1 * call, GLOBAL, NONE);
    expectSameDecisions(da, db);
    expectSameDecisions(da, a.decide(eightCavs(call), call, 0.1 * call, GLOBAL, NONE));
  }
  EXPECT_EQ(a.agent().replay().size(), 0u);
  EXPECT_EQ(a.pendingCount(), 0u);
  EXPECT_EQ(a.agent().gradientSteps(), 0u);
  EXPECT_EQ(a.stats().epsilon, 1.0);  // greedy: never decayed
}

TEST(RsuController, QuarterRatioGivesOneGradientStepPerFourCalls) {
  RsuControllerOptions o = smallOptions();
  o.gradient_steps_per_decision = 0.25;
  RsuController c(o);
  // call 1: replay 0 -> no credit; from call 2 the replay holds 8 = one batch and each call
  // earns 0.25: calls 2..5 -> 1.0 -> a step at call 5; calls 6..9 -> a step at call 9.
  const std::vector<uint64_t> expected{0, 0, 0, 0, 1, 1, 1, 1, 2};
  for (size_t call = 1; call <= expected.size(); ++call) {
    c.decide(eightCavs(static_cast<int>(call)), call, 0.1 * call, GLOBAL, NONE);
    EXPECT_EQ(c.agent().gradientSteps(), expected[call - 1]) << "call " << call;
  }
  EXPECT_FALSE(std::isnan(c.stats().q_loss));
}

TEST(RsuController, FederationIsDueAfterIntervalStepsAndResetByTheGlobalModel) {
  RsuControllerOptions o = smallOptions();
  o.federation_interval_steps = 3;
  RsuController c(o);
  // one step per call from call 2 on: steps 1, 2, 3 after calls 2, 3, 4
  for (int call = 1; call <= 4; ++call) {
    EXPECT_FALSE(c.federationDue()) << "before call " << call;
    c.decide(eightCavs(call), call, 0.1 * call, GLOBAL, NONE);
  }
  EXPECT_TRUE(c.federationDue());
  EXPECT_EQ(c.samplesSinceFederation(), 24u);  // calls 2..4 close 8 transitions each
  c.loadGlobalModel(c.exportModel(), 5);
  EXPECT_FALSE(c.federationDue());
  EXPECT_EQ(c.samplesSinceFederation(), 0u);
  EXPECT_EQ(c.federationRound(), 1u);
  EXPECT_EQ(c.decide(eightCavs(5), 5, 0.5, GLOBAL, NONE).model_version, 5u);
  c.decide(eightCavs(6), 6, 0.6, GLOBAL, NONE);
  EXPECT_FALSE(c.federationDue());  // 2 steps since the round
  c.decide(eightCavs(7), 7, 0.7, GLOBAL, NONE);
  EXPECT_TRUE(c.federationDue());   // 3 steps
}

TEST(RsuController, NoFederationWhenTheIntervalIsZero) {
  RsuControllerOptions o = smallOptions();
  o.federation_interval_steps = 0;
  RsuController c(o);
  for (int call = 1; call <= 4; ++call) c.decide(eightCavs(call), call, 0.1, GLOBAL, NONE);
  EXPECT_EQ(c.agent().gradientSteps(), 3u);
  EXPECT_FALSE(c.federationDue());
}

TEST(RsuController, APersonalHeadStaysLocalWhenTheGlobalModelIsLoaded) {
  RsuControllerOptions other = smallOptions();
  other.pdqn.seed = 99;  // other weights, same layout
  const ModelBlob global = RsuController(other).exportModel();
  RsuControllerOptions o = smallOptions();
  o.personal_head_layers = 1;
  RsuController c(o);
  const ModelBlob own = c.exportModel();
  const auto head = c.agent().headSpans(1);
  ASSERT_EQ(head.size(), 2u);  // each network's output Linear (no batch norm after it)
  std::vector<bool> in_head(own.values.size(), false);
  for (const auto& span : head)
    for (auto i = span.begin; i < span.begin + span.count; ++i) in_head[static_cast<size_t>(i)] = true;
  c.loadGlobalModel(global, 1);
  const ModelBlob loaded = c.exportModel();
  size_t kept = 0;
  for (size_t i = 0; i < loaded.values.size(); ++i) {
    ASSERT_EQ(loaded.values[i], in_head[i] ? own.values[i] : global.values[i]) << "value " << i;
    kept += in_head[i] && own.values[i] != global.values[i];
  }
  EXPECT_GT(kept, 0u);  // the two heads differed, so keeping one is seen
  EXPECT_EQ(c.modelVersion(), 1u);

  RsuController whole(smallOptions());  // 0, the paper: the whole global model
  whole.loadGlobalModel(global, 1);
  EXPECT_EQ(whole.exportModel().values, global.values);

  o.personal_head_layers = 3;  // hidden {16, 16}: three Linear layers, none left to share
  expectInvalid([&] { RsuController refused(o); }, "personal_head_layers 3");
}

TEST(RsuController, RefusesABadGlobalModelAndKeepsTheLocalOne) {
  RsuControllerOptions other = smallOptions();
  other.pdqn.hidden_sizes = {8};
  const ModelBlob foreign = RsuController(other).exportModel();
  RsuController c(smallOptions());
  c.loadGlobalModel(c.exportModel(), 2);
  const ModelBlob local = c.exportModel();
  expectInvalid([&] { c.loadGlobalModel(foreign, 3); }, "layout");
  ModelBlob broken = local;
  broken.values[5] = static_cast<float>(NaN);
  expectInvalid([&] { c.loadGlobalModel(broken, 3); }, "value 5");
  expectInvalid([&] { c.loadGlobalModel(local, 1); }, "older");
  EXPECT_EQ(c.exportModel().values, local.values);
  EXPECT_EQ(c.modelVersion(), 2u);
  EXPECT_EQ(c.federationRound(), 1u);
}

TEST(RsuController, BadSnapshotThrowsAndLeavesTheControllerUntouched) {
  RsuController c(smallOptions()), twin(smallOptions());
  c.decide(eightCavs(1), 1, 0.1, GLOBAL, NONE);
  twin.decide(eightCavs(1), 1, 0.1, GLOBAL, NONE);
  RoadSnapshot nan_speed = eightCavs(2);
  nan_speed.vehicles[3].speed_mps = NaN;
  expectInvalid([&] { c.decide(nan_speed, 2, 0.2, GLOBAL, NONE); }, "'c3': speed_mps");
  RoadSnapshot bad_lane = eightCavs(2);
  bad_lane.vehicles[1].lane = 6;
  expectInvalid([&] { c.decide(bad_lane, 2, 0.2, GLOBAL, NONE); }, "'c1': lane 6");
  RoadSnapshot no_accel_length = eightCavs(2);  // passes the snapshot check, not the reward's
  no_accel_length.vehicles[0].lane = 0;
  no_accel_length.vehicles[0].on_accel_lane = true;
  no_accel_length.vehicles[0].lateral_m = -1.6;
  expectInvalid([&] { c.decide(no_accel_length, 2, 0.2, GLOBAL, NONE); },
                "'c0': CAV situation: 'accel_lane.length'");
  RoadSnapshot four_lanes = eightCavs(2);
  four_lanes.num_lanes = 4;
  expectInvalid([&] { c.decide(four_lanes, 2, 0.2, GLOBAL, NONE); }, "num_lanes");
  expectInvalid([&] { c.decide(eightCavs(2), 2, NaN, GLOBAL, NONE); }, "time_s");
  EXPECT_EQ(c.pendingCount(), 8u);
  EXPECT_EQ(c.stats().decisions, 1u);
  // Same next call as a twin that never saw the bad input: same decisions, same replay.
  expectSameDecisions(c.decide(eightCavs(2), 2, 0.2, GLOBAL, NONE),
                      twin.decide(eightCavs(2), 2, 0.2, GLOBAL, NONE));
  ASSERT_EQ(c.agent().replay().size(), 8u);
  for (size_t i = 0; i < 8; ++i)
    EXPECT_EQ(c.agent().replay().rewardAt(i), twin.agent().replay().rewardAt(i));
  EXPECT_EQ(c.stats().epsilon, twin.stats().epsilon);
}

TEST(RsuController, ANonIncreasingStepStartsANewEpisode) {
  RsuController c(smallOptions());
  c.decide(road({cav("a", 1, 900.0)}), 10, 1.0, GLOBAL, NONE);
  c.decide(road({cav("a", 1, 900.0)}), 5, 0.5, GLOBAL, NONE);  // the bridge restarted
  EXPECT_EQ(c.agent().replay().size(), 0u);
  EXPECT_EQ(c.stats().pending_dropped, 1u);
  EXPECT_EQ(c.pendingCount(), 1u);
  c.endEpisode();
  EXPECT_EQ(c.pendingCount(), 0u);
  EXPECT_EQ(c.stats().pending_dropped, 2u);
  c.decide(road({cav("a", 1, 900.0)}), 0, 0.0, GLOBAL, NONE);
  EXPECT_EQ(c.agent().replay().size(), 0u);
}

namespace {

std::string freshDir(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::path(testing::TempDir()) / name;
  std::filesystem::remove_all(dir);
  return dir.string();
}

}  // namespace

TEST(RsuController, CheckpointRoundTripRestoresCountersAndWeights) {
  RsuControllerOptions o = smallOptions();
  o.gradient_steps_per_decision = 0.5;
  o.federation_interval_steps = 2;
  RsuController c(o);
  for (int call = 1; call <= 6; ++call) c.decide(eightCavs(call), call, 0.1, GLOBAL, NONE);
  c.loadGlobalModel(c.exportModel(), 4);
  c.decide(eightCavs(7), 7, 0.7, GLOBAL, NONE);  // credit 0.5 left, n_k = 8
  const std::string dir = freshDir("rsu_ckpt_roundtrip");
  c.saveCheckpoint(dir);

  RsuController restored(o);
  restored.loadCheckpoint(dir);
  EXPECT_EQ(restored.exportModel().values, c.exportModel().values);
  const auto a = c.stats(), b = restored.stats();
  EXPECT_EQ(b.samples_since_federation, 8u);
  EXPECT_EQ(b.samples_since_federation, a.samples_since_federation);
  EXPECT_EQ(b.gradient_steps, a.gradient_steps);
  EXPECT_EQ(b.transitions_stored, a.transitions_stored);
  EXPECT_EQ(b.decisions, a.decisions);
  EXPECT_EQ(b.epsilon, a.epsilon);
  EXPECT_EQ(b.model_version, 4u);
  EXPECT_EQ(b.federation_round, 1u);
  EXPECT_EQ(restored.pendingCount(), 0u);  // pending transitions are not checkpointed
  EXPECT_EQ(restored.federationDue(), c.federationDue());
  // Same RNG and epsilon -> same next decisions; the restored credit 0.5 + 0.5 gives a step.
  expectSameDecisions(c.decide(eightCavs(8), 8, 0.8, GLOBAL, NONE),
                      restored.decide(eightCavs(8), 8, 0.8, GLOBAL, NONE));
  EXPECT_EQ(restored.agent().gradientSteps(), c.agent().gradientSteps());
}

TEST(RsuController, OnlyTheOwnerOfACheckpointMayReplaceIt) {
  RsuControllerOptions o = smallOptions();
  const std::string dir = freshDir("rsu_ckpt_owner");
  RsuController first(o);
  first.decide(eightCavs(1), 1, 0.1, GLOBAL, NONE);
  first.saveCheckpoint(dir);
  first.saveCheckpoint(dir);  // its own checkpoint: replacing it is fine

  // A newer launch resumes from it and writes on.
  RsuController resumed(o);
  resumed.loadCheckpoint(dir);
  resumed.decide(eightCavs(2), 2, 0.2, GLOBAL, NONE);
  resumed.decide(eightCavs(3), 3, 0.3, GLOBAL, NONE);
  resumed.saveCheckpoint(dir);
  const uint64_t decisions_on_disk = resumed.stats().decisions;

  // The older process, still running (an orphan), must not overwrite the newer state ...
  first.decide(eightCavs(4), 4, 0.4, GLOBAL, NONE);
  try {
    first.saveCheckpoint(dir);
    FAIL() << "a stale process overwrote a newer checkpoint";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("another process owns it"), std::string::npos) << e.what();
  }
  // ... nor may a fresh controller that never loaded it.
  EXPECT_THROW(RsuController(o).saveCheckpoint(dir), std::runtime_error);
  RsuController check(o);
  check.loadCheckpoint(dir);
  EXPECT_EQ(check.stats().decisions, decisions_on_disk);
  resumed.saveCheckpoint(dir);  // the owner still can
}

TEST(RsuController, LoadCheckpointRefusesFilesThatAreNotOursAndStaysUntouched) {
  RsuControllerOptions o = smallOptions();
  RsuController c(o);
  c.decide(eightCavs(1), 1, 0.1, GLOBAL, NONE);
  c.decide(eightCavs(2), 2, 0.2, GLOBAL, NONE);
  const ModelBlob before = c.exportModel();
  auto refused = [&](const std::string& dir, const std::string& needle) {
    try {
      c.loadCheckpoint(dir);
      ADD_FAILURE() << "accepted " << dir;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
    EXPECT_EQ(c.exportModel().values, before.values);
    EXPECT_EQ(c.samplesSinceFederation(), 8u);
    EXPECT_EQ(c.pendingCount(), 8u);
  };
  refused(freshDir("rsu_ckpt_missing"), "cannot read");

  RsuControllerOptions other_id = o;
  other_id.rsu_id = "rsu_2";
  const std::string other_dir = freshDir("rsu_ckpt_other_id");
  RsuController(other_id).saveCheckpoint(other_dir);
  refused(other_dir, "'rsu_2'");

  RsuControllerOptions other_layout = o;
  other_layout.pdqn.hidden_sizes = {8};
  const std::string layout_dir = freshDir("rsu_ckpt_other_layout");
  RsuController(other_layout).saveCheckpoint(layout_dir);
  refused(layout_dir, "another layout");

  const std::string garbage = freshDir("rsu_ckpt_garbage");
  std::filesystem::create_directories(garbage);
  std::ofstream(garbage + "/controller.txt") << "hello\n";
  refused(garbage, "not a PALCAS RSU controller");
  std::ofstream(garbage + "/controller.txt") << "palcas_rsu_controller 1\nrsu_id rsu_1\n";
  refused(garbage, "missing key");
  std::ofstream(garbage + "/controller.txt")
      << "palcas_rsu_controller 1\nrsu_id rsu_1\nbogus 1\n";
  refused(garbage, "unknown key 'bogus'");
}

// controller.txt's format is fixed: these keys in this order (checkpoints written by every
// earlier version load), and a file from before checkpoint_id existed loads.
TEST(RsuController, ControllerFileKeepsItsKeysAndLoadsWithoutACheckpointId) {
  RsuController c(smallOptions());
  for (int call = 1; call <= 3; ++call) c.decide(eightCavs(call), call, 0.1 * call, GLOBAL, NONE);
  const std::string dir = freshDir("rsu_ckpt_format");
  c.saveCheckpoint(dir);
  std::ifstream in(dir + "/controller.txt");
  std::string line, without_id;
  std::vector<std::string> keys;
  while (std::getline(in, line)) {
    keys.push_back(line.substr(0, line.find(' ')));
    if (keys.back() != "checkpoint_id") without_id += line + "\n";
  }
  EXPECT_EQ(keys, (std::vector<std::string>{"palcas_rsu_controller", "rsu_id", "layout_checksum",
                                            "samples_since_federation", "gradient_credit",
                                            "grad_steps_at_round", "model_version",
                                            "federation_round", "transitions_stored", "decisions",
                                            "checkpoint_id"}));
  std::ofstream(dir + "/controller.txt") << without_id;
  RsuController old(smallOptions());
  old.loadCheckpoint(dir);
  EXPECT_EQ(old.stats().decisions, 3u);
  EXPECT_EQ(old.stats().transitions_stored, 16u);  // 8 CAVs closed at calls 2 and 3
  EXPECT_EQ(old.samplesSinceFederation(), 16u);

  RsuController other(smallOptions());
  std::string too_big = without_id;
  too_big.replace(too_big.find("model_version 0"), 15, "model_version 4294967296");
  std::ofstream(dir + "/controller.txt") << too_big;
  palcas_test::expectThrowNaming<std::runtime_error>([&] { other.loadCheckpoint(dir); },
                                                     "beyond 32 bits");
  EXPECT_EQ(other.stats().decisions, 0u);  // untouched
}

// preview() + adviseWith() (palcas_env's seam) is advise() with the decisions taken outside.
TEST(RsuController, AdviseWithTheNetworksDecisionsIsAdvise) {
  RsuController own(smallOptions(false)), outside(smallOptions(false));
  for (int call = 0; call < 3; ++call) {
    const RoadSnapshot r = eightCavs(call);
    const DecisionOutput a = own.advise(r, 1 + call, 0.1 * (call + 1), GLOBAL, NONE);
    const palcas::rsu::DecisionView view = outside.preview(r, 1 + call, 0.1 * (call + 1), GLOBAL, NONE);
    ASSERT_EQ(view.member_ids.size(), a.advisories.size());
    ASSERT_EQ(view.states.cols(), static_cast<palcas::nn::Index>(a.advisories.size()));
    std::vector<Decision> given;
    for (size_t i = 0; i < a.advisories.size(); ++i) {
      EXPECT_EQ(view.member_ids[i], a.advisories[i].vehicle_id);
      EXPECT_TRUE(view.states.col(static_cast<palcas::nn::Index>(i)).isApprox(stateOf(smallOptions(), r, view.member_ids[i])));
      given.push_back(a.advisories[i].decision);
    }
    expectSameDecisions(a, outside.adviseWith(r, 1 + call, 0.1 * (call + 1), GLOBAL, NONE, given));
  }
}

TEST(RsuController, PreviewShowsTheClosuresAndChangesNothing) {
  RsuController c(smallOptions());
  c.adviseWith(road({cav("a", 1, 900.0, 20.0, 1.0)}), 1, 0.1, GLOBAL, NONE, {Decision{Action::kKeep, 0.0f}});
  const RoadSnapshot now = road({cav("a", 1, 920.0)});
  const palcas::rsu::DecisionView view = c.preview(now, 2, 0.2, GLOBAL, NONE);
  const palcas::rsu::DecisionView again = c.preview(now, 2, 0.2, GLOBAL, NONE);  // nothing changed
  ASSERT_EQ(view.closures.size(), 1u);
  ASSERT_EQ(again.closures.size(), 1u);
  EXPECT_EQ(view.closures[0].id, "a");
  EXPECT_NEAR(view.closures[0].reward, R_FAST, 1e-6);
  EXPECT_FALSE(view.closures[0].done);
  EXPECT_EQ(c.agent().replay().size(), 0u);
  // The given decisions must match the members; a wrong count changes nothing.
  expectInvalid([&] { c.adviseWith(now, 2, 0.2, GLOBAL, NONE, {}); }, "0 decisions for 1 members");
  EXPECT_EQ(c.agent().replay().size(), 0u);
  const DecisionOutput out = c.adviseWith(now, 2, 0.2, GLOBAL, NONE, {Decision{Action::kLaneRight, 0.0f}});
  EXPECT_EQ(out.advisories[0].decision.action, Action::kKeep);  // lane 1: no right, masked as advise() does
  EXPECT_EQ(c.agent().replay().size(), 1u);                     // the transition stored, as advise() would
  EXPECT_NEAR(c.stats().sum_reward, view.closures[0].reward, 1e-9);
  // A step not after the last starts an episode: it closes nothing.
  EXPECT_TRUE(c.preview(now, 1, 0.1, GLOBAL, NONE).closures.empty());
}

TEST(RsuController, ImpossibleLaneChangesBecomeKeep) {
  using palcas::rsu::maskImpossibleLaneChange;
  const Decision left{Action::kLaneLeft, 0.0f}, right{Action::kLaneRight, 0.0f};
  const Decision accel{Action::kAccelerate, -1.5f};
  EXPECT_EQ(maskImpossibleLaneChange(left, 5, 5).action, Action::kKeep);   // leftmost of 5
  EXPECT_EQ(maskImpossibleLaneChange(left, 4, 5).action, Action::kLaneLeft);
  EXPECT_EQ(maskImpossibleLaneChange(left, 0, 5).action, Action::kLaneLeft);  // merge: 0 -> 1
  EXPECT_EQ(maskImpossibleLaneChange(right, 1, 5).action, Action::kKeep);  // exit lane
  EXPECT_EQ(maskImpossibleLaneChange(right, 0, 5).action, Action::kKeep);  // acceleration lane
  EXPECT_EQ(maskImpossibleLaneChange(right, 2, 5).action, Action::kLaneRight);
  EXPECT_EQ(maskImpossibleLaneChange(left, 1, 1).action, Action::kKeep);   // one-lane road
  const Decision kept = maskImpossibleLaneChange(accel, 5, 5);
  EXPECT_EQ(kept.action, Action::kAccelerate);
  EXPECT_FLOAT_EQ(kept.accel_mps2, -1.5f);
}

TEST(RsuController, PossibleActionsRuleOutLaneChangesOffTheMainline) {
  using palcas::rsu::possibleActions;
  EXPECT_EQ(possibleActions(1, 5), NO_RIGHT);   // exit lane
  EXPECT_EQ(possibleActions(0, 5), NO_RIGHT);   // acceleration lane: left merges
  EXPECT_EQ(possibleActions(3, 5), ALL_ACTIONS);
  EXPECT_EQ(possibleActions(5, 5), NO_LEFT);    // leftmost
  EXPECT_EQ(possibleActions(1, 1), NO_RIGHT & NO_LEFT);  // one-lane road: accelerate, keep
}

TEST(RsuController, ExitBoundCavsAreNotSentLeftWithinTheSetDistance) {
  using palcas::rsu::allowedActions;
  VehicleSnapshot exiting = cav("x", 3, 1000.0);
  exiting.distance_to_exit_m = 500.0;
  EXPECT_EQ(allowedActions(exiting, 5, 0.0), ALL_ACTIONS);  // off (paper)
  EXPECT_EQ(allowedActions(exiting, 5, 600.0), NO_LEFT);
  EXPECT_EQ(allowedActions(exiting, 5, 500.0), ALL_ACTIONS);  // not closer than the distance
  EXPECT_EQ(allowedActions(cav("t", 3, 1000.0), 5, 1e9), ALL_ACTIONS);  // through: no exit
  exiting.lane = 1;
  EXPECT_EQ(allowedActions(exiting, 5, 600.0), NO_RIGHT & NO_LEFT);
  VehicleSnapshot merging = mergingCav("m", 850.0);
  merging.distance_to_exit_m = 300.0;
  EXPECT_EQ(allowedActions(merging, 5, 1e9), NO_RIGHT) << "the merge (left from lane 0) stays allowed";

  // In the decision: a left advised to the exit-bound member becomes KEEP, the others keep
  // theirs, and the stored transition's valid actions leave it out.
  RsuControllerOptions o = smallOptions();
  o.no_left_for_exit_within_m = 600.0;
  o.gradient_steps_per_decision = 0;
  RsuController c(o);
  VehicleSnapshot near = cav("a", 3, 1000.0), far = cav("b", 3, 1100.0);
  near.distance_to_exit_m = 400.0;
  far.distance_to_exit_m = 900.0;
  const Decision left{Action::kLaneLeft, 0.0f};
  const auto advised = [](const DecisionOutput& out) {
    std::vector<Action> actions;
    for (const auto& a : out.advisories) actions.push_back(a.decision.action);
    return actions;
  };
  const RoadSnapshot first = road({near, far, cav("c", 2, 1200.0), merging});
  c.preview(first, 1, 0.1, GLOBAL, NONE);
  EXPECT_EQ(advised(c.adviseWith(first, 1, 0.1, GLOBAL, NONE, {left, left, left, left})),
            (std::vector<Action>{Action::kKeep, Action::kLaneLeft, Action::kLaneLeft, Action::kLaneLeft}));
  near.x_m += 20.0;
  far.x_m += 20.0;
  c.adviseWith(road({near, far, cav("c", 2, 1220.0), merging}), 2, 0.2, GLOBAL, NONE, {left, left, left, left});
  const auto& replay = c.agent().replay();
  ASSERT_EQ(replay.size(), 4u);  // a, b, c, m in id order
  EXPECT_EQ(int(replay.nextValidActionsAt(0)), int(NO_LEFT));
  EXPECT_EQ(int(replay.nextValidActionsAt(1)), int(ALL_ACTIONS));
  EXPECT_EQ(int(replay.nextValidActionsAt(3)), int(NO_RIGHT));

  o.no_left_for_exit_within_m = -1.0;
  palcas_test::expectThrowNaming<std::invalid_argument>([&] { RsuController bad(o); }, "no_left_for_exit_within_m");
  o.no_left_for_exit_within_m = std::numeric_limits<double>::quiet_NaN();
  palcas_test::expectThrowNaming<std::invalid_argument>([&] { RsuController bad(o); }, "no_left_for_exit_within_m");
}

TEST(RsuController, ALaneChangeThatDoesNotServeTheRouteCostsItsTransition) {
  using palcas::rsu::servesRoute;
  VehicleSnapshot through = cav("t", 3, 1000.0), exiting = cav("x", 3, 1050.0);
  exiting.distance_to_exit_m = 700.0;
  const VehicleSnapshot merging = mergingCav("m", 850.0);
  EXPECT_FALSE(servesRoute(through, Action::kLaneLeft));
  EXPECT_FALSE(servesRoute(through, Action::kLaneRight));
  EXPECT_FALSE(servesRoute(exiting, Action::kLaneLeft)) << "away from its exit";
  EXPECT_TRUE(servesRoute(exiting, Action::kLaneRight));
  EXPECT_TRUE(servesRoute(merging, Action::kLaneLeft)) << "the merge";
  EXPECT_TRUE(servesRoute(through, Action::kAccelerate));
  EXPECT_TRUE(servesRoute(through, Action::kKeep));

  // The same two decisions with and without the cost: only the through CAV's change left and
  // the exit-bound CAV's change left pay it, whichever way their transitions close.
  const Decision left{Action::kLaneLeft, 0.0f}, right{Action::kLaneRight, 0.0f}, keep{Action::kKeep, 0.0f};
  RsuControllerOptions o = smallOptions();
  o.gradient_steps_per_decision = 0;
  RsuController free_changes(o);
  o.lane_change_cost = 0.5;
  RsuController costly(o);
  VehicleSnapshot away = exiting;
  away.id = "y";
  const RoadSnapshot first = road({through, exiting, away, merging});
  const std::vector<Decision> advice{left, right, left, left};  // members in road order: t, x, y, m
  VehicleSnapshot t2 = through, x2 = exiting;
  t2.x_m += 20.0;
  x2.x_m += 20.0;
  const RoadSnapshot second = road({t2, x2, mergingCav("m", 870.0)});  // y vanished (not closed yet)
  for (RsuController* c : {&free_changes, &costly}) {
    c->adviseWith(first, 1, 0.1, GLOBAL, NONE, advice);
  }
  const palcas::rsu::DecisionView view = costly.preview(second, 2, 0.2, GLOBAL, NONE);
  for (RsuController* c : {&free_changes, &costly}) {
    c->adviseWith(second, 2, 0.2, GLOBAL, NONE, {keep, keep, keep});
  }
  const auto& paid = costly.agent().replay();
  const auto& unpaid = free_changes.agent().replay();
  ASSERT_EQ(paid.size(), 3u);  // m, t, x
  ASSERT_EQ(unpaid.size(), 3u);
  EXPECT_NEAR(paid.rewardAt(0), unpaid.rewardAt(0), 1e-6) << "the merge is free";
  EXPECT_NEAR(paid.rewardAt(1), unpaid.rewardAt(1) - 0.5, 1e-6) << "the through CAV's change left";
  EXPECT_NEAR(paid.rewardAt(2), unpaid.rewardAt(2), 1e-6) << "towards the exit is free";
  ASSERT_EQ(view.closures.size(), 3u);
  for (size_t i = 0; i < 3; ++i) EXPECT_NEAR(view.closures[i].reward, paid.rewardAt(i), 1e-6) << "preview = stored";
  // y, gone from the road, closes at the next decision as having left it: it pays too.
  for (RsuController* c : {&free_changes, &costly}) {
    c->adviseWith(road({}), 3, 0.3, GLOBAL, NONE, {});
  }
  ASSERT_EQ(paid.size(), unpaid.size());
  bool y_paid = false;
  for (size_t i = 3; i < paid.size(); ++i)
    y_paid = y_paid || std::abs(paid.rewardAt(i) - (unpaid.rewardAt(i) - 0.5f)) < 1e-6f;
  EXPECT_TRUE(y_paid) << "an exit-bound CAV's change away from its exit costs, however it closes";

  o.lane_change_cost = -0.1;
  palcas_test::expectThrowNaming<std::invalid_argument>([&] { RsuController bad(o); }, "lane_change_cost");
  o.lane_change_cost = std::numeric_limits<double>::quiet_NaN();
  palcas_test::expectThrowNaming<std::invalid_argument>([&] { RsuController bad(o); }, "lane_change_cost");
}

TEST(RsuController, ACavWhoseLaneJustChangedIsNotSentAcrossAgain) {
  using palcas::rsu::dwellAllowedActions;
  VehicleSnapshot through = cav("t", 3, 1000.0), exiting = cav("x", 3, 1000.0);
  exiting.distance_to_exit_m = 700.0;
  EXPECT_EQ(dwellAllowedActions(through, 5.0, 0.0), ALL_ACTIONS);  // off (paper)
  EXPECT_EQ(dwellAllowedActions(through, 5.0, 30.0), NO_LEFT & NO_RIGHT);
  EXPECT_EQ(dwellAllowedActions(through, 30.0, 30.0), ALL_ACTIONS);  // the dwell is over
  EXPECT_EQ(dwellAllowedActions(exiting, 5.0, 30.0), NO_LEFT) << "towards the exit stays allowed";
  EXPECT_EQ(dwellAllowedActions(mergingCav("m", 850.0), 0.0, 30.0), ALL_ACTIONS) << "the merge stays allowed";

  RsuControllerOptions o = smallOptions();
  o.lane_change_dwell_s = 30.0;
  o.gradient_steps_per_decision = 0;
  RsuController c(o);
  const Decision left{Action::kLaneLeft, 0.0f}, right{Action::kLaneRight, 0.0f};
  const auto actionsOf = [](const DecisionOutput& out) {
    std::vector<Action> actions;
    for (const auto& a : out.advisories) actions.push_back(a.decision.action);
    return actions;
  };
  const auto at = [&](double x, int lane_t, int lane_x) {
    VehicleSnapshot t = cav("t", lane_t, x), e = cav("x", lane_x, x + 100.0);
    e.distance_to_exit_m = 700.0 - (x - 1000.0);
    return road({t, e});
  };
  // Never seen to change: both may change; then both change lanes (t left, x right).
  EXPECT_EQ(actionsOf(c.adviseWith(at(1000.0, 3, 3), 1, 1.0, GLOBAL, NONE, {left, right})),
            (std::vector<Action>{Action::kLaneLeft, Action::kLaneRight}));
  // 10 s after: t's change back becomes KEEP; x may go on towards its exit, not back left.
  EXPECT_EQ(actionsOf(c.adviseWith(at(1100.0, 4, 2), 2, 11.0, GLOBAL, NONE, {right, right})),
            (std::vector<Action>{Action::kKeep, Action::kLaneRight}));
  EXPECT_EQ(actionsOf(c.adviseWith(at(1200.0, 4, 2), 3, 20.0, GLOBAL, NONE, {right, left})),
            (std::vector<Action>{Action::kKeep, Action::kKeep}));
  // The stored transitions' next states (at 11 s, the lanes just changed) leave them out.
  const auto& replay = c.agent().replay();
  ASSERT_EQ(replay.size(), 4u);  // t, x at 11 s; t, x at 20 s
  EXPECT_EQ(int(replay.nextValidActionsAt(0)), int(NO_LEFT & NO_RIGHT));
  EXPECT_EQ(int(replay.nextValidActionsAt(1)), int(NO_LEFT));
  // 30 s after the change: free again.
  EXPECT_EQ(actionsOf(c.adviseWith(at(1300.0, 4, 2), 4, 41.0, GLOBAL, NONE, {right, left})),
            (std::vector<Action>{Action::kLaneRight, Action::kLaneLeft}));
  // A new episode forgets the lanes seen.
  c.adviseWith(at(1000.0, 3, 3), 5, 42.0, GLOBAL, NONE, {left, right});
  EXPECT_EQ(actionsOf(c.adviseWith(at(1000.0, 2, 2), 1, 0.0, GLOBAL, NONE, {left, left})),
            (std::vector<Action>{Action::kLaneLeft, Action::kLaneLeft}));

  o.lane_change_dwell_s = -1.0;
  palcas_test::expectThrowNaming<std::invalid_argument>([&] { RsuController bad(o); }, "lane_change_dwell_s");
  o.lane_change_dwell_s = std::numeric_limits<double>::infinity();
  palcas_test::expectThrowNaming<std::invalid_argument>([&] { RsuController bad(o); }, "lane_change_dwell_s");
}

TEST(RsuController, TransitionsStoreTheValidActionsOfTheirNextState) {
  // Lanes chosen at the edges of a 5-lane road; the mask is that of s' (the lane now).
  RsuController c(smallOptions());
  VehicleSnapshot merging = mergingCav("d", 850.0);
  c.decide(road({cav("a", 1, 900.0), cav("b", 5, 1000.0), cav("c", 3, 1100.0), merging,
                 cav("e", 5, 1200.0), cav("f", 1, 1590.0), cav("g", 2, 1300.0)}),
           1, 0.1, GLOBAL, NONE);
  merging.x_m = 870.0;
  VehicleOutcomes events;
  events.collided = {"e"};  // terminal: s' = s, in lane 5
  c.decide(road({cav("a", 1, 920.0), cav("b", 5, 1020.0), cav("c", 5, 1120.0), merging,
                 cav("f", 2, 1605.0) /* handed over */, cav("g", 3, 1320.0)}),
           2, 0.2, GLOBAL, events);
  // Stored in id order a..g.
  const std::vector<ActionMask> expected{NO_RIGHT, NO_LEFT, NO_LEFT, NO_RIGHT,
                                         NO_LEFT,  ALL_ACTIONS, ALL_ACTIONS};
  const auto& replay = c.agent().replay();
  ASSERT_EQ(replay.size(), expected.size());
  for (size_t i = 0; i < expected.size(); ++i)
    EXPECT_EQ(int(replay.nextValidActionsAt(i)), int(expected[i])) << "transition " << i;
  // Each mask is what the agent's old decode read out of that transition's s'.
  palcas::Rng rng(2);
  ReplayBatch batch;
  replay.sample(64, rng, batch);
  for (Index j = 0; j < 64; ++j)
    EXPECT_EQ(int(batch.next_valid_actions[j]), int(oldDecodedMask(batch.next_states.col(j), 5)))
        << j;
}

TEST(RsuController, TdTargetsWithStoredMasksEqualTheOnesTheOldDecodeGave) {
  // Twenty CAVs over all lanes and the acceleration lane, three decisions: 40 transitions.
  RsuControllerOptions o = smallOptions();
  o.pdqn.td_target_valid_actions = true;
  o.gradient_steps_per_decision = 0;  // the weights stay those of seed 7
  RsuController c(o);
  for (int call = 1; call <= 3; ++call) {
    std::vector<VehicleSnapshot> v;
    for (int i = 0; i < 20; ++i) {
      const std::string id = "c" + std::to_string(10 + i);
      const int lane = (i + call) % 6;
      const double x = 820.0 + 38.0 * i + 9.0 * call, speed = 12.0 + i, a = 0.1 * (i % 5) - 0.2;
      v.push_back(lane == 0 ? mergingCav(id, x, speed, a) : cav(id, lane, x, speed, a));
    }
    c.decide(road(v), call, 0.1 * call, GLOBAL, NONE);
  }
  ASSERT_EQ(c.agent().replay().size(), 40u);
  palcas::Rng rng(3);
  ReplayBatch batch;
  c.agent().replay().sample(200, rng, batch);

  // An agent taught that lane changes pay (+5, terminal), so they have the largest Q in
  // many next states and the masks decide the max. 300 steps = 100 hard copies (C = 3):
  // the targets then equal the online networks, and evaluate() gives the
  // Q_target(s', mu_target(s')) that the old decode masked.
  palcas::PdqnConfig taught = o.pdqn;
  taught.target_update_steps = 3;
  PdqnAgent agent(taught);
  for (Index j = 0; j < 64; ++j) {
    const Decision change{j % 2 == 0 ? Action::kLaneLeft : Action::kLaneRight, 0.0f};
    agent.remember(batch.states.col(j), change, 5.0f, batch.states.col(j), ALL_ACTIONS, true);
  }
  for (int i = 0; i < 300; ++i) agent.update();
  Matrix q, accel, with_stored_masks;
  agent.evaluate(batch.next_states, q, accel);
  agent.nextStateValues(batch.next_states, batch.next_valid_actions, with_stored_masks);
  Matrix old_masked = q;
  oldMaskInvalidNextActions(batch.next_states, 5, old_masked);
  const Matrix old_values = old_masked.colwise().maxCoeff();
  const float gamma = o.pdqn.gamma;
  auto tdTargets = [&](const Matrix& values) -> Matrix {
    return batch.rewards.array() + gamma * (1.0f - batch.dones.array()) * values.array();
  };
  const Matrix y_new = tdTargets(with_stored_masks), y_old = tdTargets(old_values);
  ASSERT_EQ(y_new.cols(), 200);
  EXPECT_EQ(std::memcmp(y_new.data(), y_old.data(), 200 * sizeof(float)), 0);
  EXPECT_EQ(std::memcmp(with_stored_masks.data(), old_values.data(), 200 * sizeof(float)), 0);
  // Not vacuous: some sampled next state's best action is one the mask rules out.
  EXPECT_GT((q.colwise().maxCoeff().array() != old_values.array()).count(), 0);
}

TEST(RsuController, ResumesACheckpointWrittenBeforeTheMasksWereStored) {
  RsuControllerOptions o = smallOptions();
  o.pdqn.td_target_valid_actions = true;
  RsuController c(o);
  for (int call = 1; call <= 4; ++call) c.decide(eightCavs(call), call, 0.1 * call, GLOBAL, NONE);
  const std::string dir = freshDir("rsu_ckpt_masks"), old_dir = freshDir("rsu_ckpt_no_masks");
  c.saveCheckpoint(dir);
  std::filesystem::copy(dir, old_dir);
  palcas_test::dropMasksFromCheckpoint(old_dir + "/agent.ckpt");

  RsuController resumed(o), resumed_old(o);
  resumed.loadCheckpoint(dir);
  resumed_old.loadCheckpoint(old_dir);  // the masks rebuilt from the lanes of the s'
  const auto& replay = resumed_old.agent().replay();
  ASSERT_EQ(replay.size(), 24u);
  for (size_t i = 0; i < replay.size(); ++i)
    EXPECT_EQ(int(replay.nextValidActionsAt(i)), int(c.agent().replay().nextValidActionsAt(i)))
        << i;
  // Hence the same training from there on.
  for (int call = 5; call <= 8; ++call)
    for (RsuController* r : {&resumed, &resumed_old})
      r->decide(eightCavs(call), call, 0.1 * call, GLOBAL, NONE);
  EXPECT_GT(resumed_old.agent().gradientSteps(), c.agent().gradientSteps());
  EXPECT_EQ(resumed_old.exportModel().values, resumed.exportModel().values);
}

TEST(RsuController, AdviseDefersTheGradientStepsToLearn) {
  RsuControllerOptions o = smallOptions();
  o.gradient_steps_per_decision = 1.0;
  RsuController c(o);
  c.advise(eightCavs(1), 1, 0.1, GLOBAL, NONE);
  c.advise(eightCavs(2), 2, 0.2, GLOBAL, NONE);  // closes 8 transitions: replay holds a batch
  EXPECT_EQ(c.agent().gradientSteps(), 0u);      // advise never learns
  c.learn();
  EXPECT_EQ(c.agent().gradientSteps(), 1u);
}
