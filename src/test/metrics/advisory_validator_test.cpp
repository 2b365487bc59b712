// validateAdvisory as a table: one row per rejection reason and per lane edge, plus advisories
// that must pass. Bridge step 10 and the paper's bounds [-4.5, 2.6] m/s^2 unless a row says.
#include "palcas_core/metrics/advisory_validator.h"
#include "msg_constants.h"

#include <gtest/gtest.h>

#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <regex>
#include <string>
#include <vector>

#include "common/throws_naming.h"

using namespace palcas::metrics;

namespace {

constexpr double NaN = std::numeric_limits<double>::quiet_NaN();
constexpr double INF = std::numeric_limits<double>::infinity();
constexpr int LEFT = 0, RIGHT = 1, ACCEL = 2, KEEP = 3;
constexpr std::uint64_t STEP = 10;

KnownVehicle cavInLane(int lane, int num_lanes = 5) { return {true, true, lane, false, num_lanes}; }
KnownVehicle cavOnAccelLane() { return {true, true, 0, true, 5}; }
KnownVehicle cavOnRamp() { return {true, true, 0, false, 5}; }

struct Row {
  const char* name;
  int action;
  double accel_mps2;
  KnownVehicle vehicle;
  std::optional<RejectionReason> reason;  ///< nullopt = must be accepted
  const char* detail_part = "";           ///< text the detail must contain
  std::uint64_t answers_step = STEP;
  std::uint64_t max_age = 0;
  bool already_advised = false;
};

}  // namespace

TEST(AdvisoryValidator, Table) {
  using R = RejectionReason;
  const KnownVehicle gone{false, true, 3, false, 5};
  const KnownVehicle human{true, false, 3, false, 5};
  const std::vector<Row> rows = {
      // Accepted.
      {"keep in lane 3", KEEP, 0.0, cavInLane(3), std::nullopt},
      {"accelerate at the upper bound 2.6", ACCEL, 2.6, cavInLane(2), std::nullopt},
      {"accelerate at the lower bound -4.5", ACCEL, -4.5, cavInLane(2), std::nullopt},
      {"left from lane 4 of 5", LEFT, 0.0, cavInLane(4), std::nullopt},
      {"right from lane 2", RIGHT, 0.0, cavInLane(2), std::nullopt},
      {"left from the accel lane into lane 1", LEFT, 0.0, cavOnAccelLane(), std::nullopt},
      {"keep on a ramp", KEEP, 0.0, cavOnRamp(), std::nullopt},
      {"accelerate on the accel lane", ACCEL, 1.0, cavOnAccelLane(), std::nullopt},
      {"keep ignores a NaN acceleration", KEEP, NaN, cavInLane(3), std::nullopt},
      {"left ignores an infinite acceleration", LEFT, INF, cavInLane(3), std::nullopt},
      {"right ignores an out-of-range acceleration", RIGHT, 9.0, cavInLane(3), std::nullopt},
      {"one step old with max age 1", KEEP, 0.0, cavInLane(3), std::nullopt, "", STEP - 1, 1},
      // One row per reason.
      {"unknown vehicle", KEEP, 0.0, gone, R::kUnknownVehicle, "not on the road"},
      {"human-driven", KEEP, 0.0, human, R::kNotACav, "human-driven"},
      {"NaN acceleration", ACCEL, NaN, cavInLane(3), R::kNotFinite, "acceleration nan"},
      {"infinite acceleration", ACCEL, -INF, cavInLane(3), R::kNotFinite, "-inf"},
      {"acceleration 3.1", ACCEL, 3.1, cavInLane(3), R::kAccelOutOfRange,
       "acceleration 3.1 m/s^2 outside [-4.5, 2.6]"},
      {"acceleration -4.6", ACCEL, -4.6, cavInLane(3), R::kAccelOutOfRange, "-4.6 m/s^2"},
      {"one step old", KEEP, 0.0, cavInLane(3), R::kStaleStep, "answers step 9, 1 steps old",
       STEP - 1},
      {"three steps old with max age 2", KEEP, 0.0, cavInLane(3), R::kStaleStep, "max age 2",
       STEP - 3, 2},
      {"future step", KEEP, 0.0, cavInLane(3), R::kStaleStep, "future", STEP + 1},
      {"action code 4", 4, 0.0, cavInLane(3), R::kUnknownAction, "action code 4"},
      {"action code -1", -1, 0.0, cavInLane(3), R::kUnknownAction, "action code -1"},
      {"duplicate", KEEP, 0.0, cavInLane(3), R::kDuplicate, "already advised", STEP, 0, true},
      // Lane edges.
      {"left from lane 5 of 5", LEFT, 0.0, cavInLane(5), R::kNoSuchLane, "leftmost of 5"},
      {"left from lane 3 of 3", LEFT, 0.0, cavInLane(3, 3), R::kNoSuchLane, "leftmost of 3"},
      {"right from lane 1", RIGHT, 0.0, cavInLane(1), R::kNoSuchLane, "lane_right from lane 1"},
      {"right from the accel lane", RIGHT, 0.0, cavOnAccelLane(), R::kNoSuchLane,
       "acceleration lane"},
      {"left from a ramp", LEFT, 0.0, cavOnRamp(), R::kNoSuchLane, "lane_left from a ramp"},
      {"right from a ramp", RIGHT, 0.0, cavOnRamp(), R::kNoSuchLane, "lane_right from a ramp"},
      {"single lane road, left", LEFT, 0.0, cavInLane(1, 1), R::kNoSuchLane, "leftmost of 1"},
      // Order: the first failed rule is reported.
      {"unknown vehicle before bad action", 7, NaN, gone, R::kUnknownVehicle, ""},
      {"human before stale", KEEP, 0.0, human, R::kNotACav, "", STEP - 5},
      {"stale before duplicate", KEEP, 0.0, cavInLane(3), R::kStaleStep, "", STEP - 1, 0, true},
      {"duplicate before bad action", 9, 0.0, cavInLane(3), R::kDuplicate, "", STEP, 0, true},
  };
  for (const auto& r : rows) {
    SCOPED_TRACE(r.name);
    const AdvisoryRequest advisory{"cav_7", r.action, r.accel_mps2, r.answers_step, "rsu_1"};
    AdvisoryLimits limits;
    limits.max_step_age = r.max_age;
    std::unordered_set<std::string> advised = {"other"};
    if (r.already_advised) advised.insert("cav_7");
    const auto verdict = validateAdvisory(advisory, STEP, r.vehicle, limits, advised);
    if (!r.reason) {
      EXPECT_TRUE(verdict.accepted) << verdict.detail;
      EXPECT_EQ(verdict.detail, "");
      continue;
    }
    EXPECT_FALSE(verdict.accepted);
    EXPECT_EQ(rejectionReasonName(verdict.reason), rejectionReasonName(*r.reason));
    EXPECT_NE(verdict.detail.find(r.detail_part), std::string::npos) << verdict.detail;
    EXPECT_FALSE(verdict.detail.empty());
  }
}

TEST(AdvisoryValidator, CustomBoundsAppearInTheDetail) {
  AdvisoryLimits limits;
  limits.accel_min_mps2 = -3.0;
  limits.accel_max_mps2 = 1.5;
  const auto verdict =
      validateAdvisory({"v", ACCEL, 2.0, STEP, "rsu_0"}, STEP, cavInLane(2), limits, {});
  EXPECT_FALSE(verdict.accepted);
  EXPECT_EQ(verdict.reason, RejectionReason::kAccelOutOfRange);
  EXPECT_EQ(verdict.detail, "acceleration 2 m/s^2 outside [-3, 1.5]");
}

TEST(AdvisoryValidator, ThrowsOnInconsistentInputs) {
  const AdvisoryRequest keep{"v", KEEP, 0.0, STEP, "rsu_0"};
  AdvisoryLimits swapped;
  swapped.accel_min_mps2 = 2.6;
  swapped.accel_max_mps2 = -4.5;
  EXPECT_THROW(validateAdvisory(keep, STEP, cavInLane(2), swapped, {}), std::invalid_argument);
  AdvisoryLimits nan_limit;
  nan_limit.accel_max_mps2 = NaN;
  EXPECT_THROW(validateAdvisory(keep, STEP, cavInLane(2), nan_limit, {}), std::invalid_argument);
  // A lane that does not exist on the vehicle's road, no lanes at all, accel lane not lane 0.
  EXPECT_THROW(validateAdvisory(keep, STEP, cavInLane(6, 5), {}, {}), std::invalid_argument);
  EXPECT_THROW(validateAdvisory(keep, STEP, cavInLane(-1, 5), {}, {}), std::invalid_argument);
  EXPECT_THROW(validateAdvisory(keep, STEP, cavInLane(1, 0), {}, {}), std::invalid_argument);
  EXPECT_THROW(validateAdvisory(keep, STEP, {true, true, 2, true, 5}, {}, {}),
               std::invalid_argument);
  palcas_test::expectThrowNaming<std::invalid_argument>(
      [&] { validateAdvisory(keep, STEP, cavInLane(6, 5), {}, {}); }, "lane 6 outside 0..5");
  // A vehicle that does not exist is not checked for consistency: it is just unknown.
  const auto verdict = validateAdvisory(keep, STEP, {false, false, 99, true, 0}, {}, {});
  EXPECT_EQ(verdict.reason, RejectionReason::kUnknownVehicle);
}

using palcas::test::msgConstants;

TEST(AdvisoryValidator, ReasonCodesMatchAdvisoryRejectionMsg) {
  const auto msg = msgConstants("AdvisoryRejection.msg");
  const std::map<std::string, RejectionReason> expected = {
      {"UNKNOWN_VEHICLE", RejectionReason::kUnknownVehicle},
      {"NOT_A_CAV", RejectionReason::kNotACav},
      {"NOT_FINITE", RejectionReason::kNotFinite},
      {"ACCEL_OUT_OF_RANGE", RejectionReason::kAccelOutOfRange},
      {"NO_SUCH_LANE", RejectionReason::kNoSuchLane},
      {"STALE_STEP", RejectionReason::kStaleStep},
      {"UNKNOWN_ACTION", RejectionReason::kUnknownAction},
      {"DUPLICATE", RejectionReason::kDuplicate},
      {"UNAUTHENTICATED", RejectionReason::kUnauthenticated},
      {"GUARD_HANDED_BACK", RejectionReason::kGuardHandedBack},
      {"GUARD_INSERTION_EDGE", RejectionReason::kGuardInsertionEdge},
      {"GUARD_COOLDOWN", RejectionReason::kGuardCooldown},
      {"GUARD_BUSY_ZONE", RejectionReason::kGuardBusyZone},
      {"SUMO_REFUSED", RejectionReason::kSumoRefused}};
  for (const auto& [name, reason] : expected) {
    ASSERT_EQ(msg.count(name), 1u) << name;
    EXPECT_EQ(msg.at(name), static_cast<int>(reason)) << name;
    // The names are the lower-case message constant names.
    std::string lower = name;
    for (auto& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    EXPECT_EQ(rejectionReasonName(reason), lower);
  }
  ASSERT_EQ(msg.count("REASON_COUNT"), 1u);
  EXPECT_EQ(msg.at("REASON_COUNT"), REJECTION_REASON_COUNT);
  EXPECT_EQ(msg.size(), expected.size() + 1);
}

TEST(AdvisoryValidator, GuardRefusalsAreTheGuardsFourReasons) {
  int guard = 0;
  for (int code = 0; code < REJECTION_REASON_COUNT; ++code) {
    const auto reason = static_cast<RejectionReason>(code);
    const bool by_guard = isGuardRefusal(reason);
    guard += by_guard;
    EXPECT_EQ(by_guard, rejectionReasonName(reason).rfind("guard_", 0) == 0) << rejectionReasonName(reason);
  }
  EXPECT_EQ(guard, 4);
}
