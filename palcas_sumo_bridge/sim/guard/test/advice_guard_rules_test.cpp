// The advice guard's rules (palcas_sim/advice_guard.h) without SUMO: zones with their
// hysteresis and start-up, the floor, the advice refusals, the hand-back and the busy zones'
// change bound, each on the state it is given.
#include <gtest/gtest.h>

#include <vector>

#include "palcas_sim/advice_guard.h"

namespace {

using palcas::sim::AdviceCase;
using palcas::sim::AdviceGuard;
using palcas::sim::AdviceVerdict;
using palcas::sim::GuardCav;
using palcas::sim::GuardMemory;
using palcas::sim::GuardOptions;
using palcas::sim::HandbackChange;
using palcas::sim::HeldAcceleration;
using palcas::sim::ZoneSpeedSample;

constexpr double kStepS = 0.1;
constexpr double kTopMps = 40.0;

/// Every vehicle of zone `zone` driving `share` of its top speed.
std::vector<ZoneSpeedSample> zoneAt(int zone, double share, int vehicles = 3) {
  return std::vector<ZoneSpeedSample>(vehicles, ZoneSpeedSample{zone, share * kTopMps, kTopMps});
}

/// Options whose zones follow their traffic at once (a window of one step).
GuardOptions instantZones() {
  GuardOptions o;
  o.busy_window_s = kStepS;
  return o;
}

/// A CAV at `speed_mps` in `zone` whose lane allows `allowed_mps` (top speed kTopMps).
GuardCav cav(double speed_mps, int zone = 0, double allowed_mps = 30.0) {
  GuardCav c;
  c.speed_mps = speed_mps;
  c.top_speed_mps = kTopMps;
  c.zone = zone;
  c.allowed_speed_mps = [allowed_mps] { return allowed_mps; };
  return c;
}

/// A guard of `o` with zone 0 busy and zone 1 free (two zones).
AdviceGuard withBusyZone0(GuardOptions o = instantZones()) {
  AdviceGuard g(o);
  std::vector<ZoneSpeedSample> s = zoneAt(0, 0.2);
  const std::vector<ZoneSpeedSample> free = zoneAt(1, 1.0);
  s.insert(s.end(), free.begin(), free.end());
  g.updateZones(2, s, kStepS);
  return g;
}

AdviceCase laneChange(int zone, double time_s = 100.0) {
  AdviceCase a;
  a.lane_change = true;
  a.zone = zone;
  a.time_s = time_s;
  return a;
}

// --- Zones ---

TEST(GuardZones, FreeTrafficLeavesAZoneFree) {
  AdviceGuard g{GuardOptions{}};
  for (int i = 0; i < 1000; ++i) g.updateZones(3, zoneAt(1, 0.95), kStepS);
  for (int k = 0; k < 3; ++k) EXPECT_FALSE(g.zoneBusy(k)) << k;
  EXPECT_NEAR(g.zoneSpeedShare(1), 0.95, 5e-3);
  EXPECT_DOUBLE_EQ(g.zoneSpeedShare(0), 1.0);  // empty: keeps its start
  EXPECT_EQ(g.counters().zone_steps, 3000u);
  EXPECT_EQ(g.counters().busy_zone_steps, 0u);
}

TEST(GuardZones, SlowTrafficMakesAZoneBusyOnlyOverTheWindow) {
  GuardOptions o;  // 0.8 / 0.88 over 30 s
  AdviceGuard g(o);
  // Share 0.5 from a start of 1: below 0.8 after ln(0.6) / ln(1 - 1/300), about 153 steps.
  for (int i = 0; i < 100; ++i) g.updateZones(2, zoneAt(0, 0.5), kStepS);
  EXPECT_FALSE(g.zoneBusy(0)) << "one slow moment flipped it: share " << g.zoneSpeedShare(0);
  for (int i = 0; i < 100; ++i) g.updateZones(2, zoneAt(0, 0.5), kStepS);
  EXPECT_TRUE(g.zoneBusy(0)) << "share " << g.zoneSpeedShare(0);
  EXPECT_FALSE(g.zoneBusy(1));
  EXPECT_GT(g.counters().busy_zone_steps, 0u);
  EXPECT_LT(g.counters().busy_zone_steps, 100u);
}

TEST(GuardZones, ABusyZoneStaysBusyUntilAboveTheLeaveShare) {
  AdviceGuard g(instantZones());
  g.updateZones(1, zoneAt(0, 0.5), kStepS);
  ASSERT_TRUE(g.zoneBusy(0));
  g.updateZones(1, zoneAt(0, 0.85), kStepS);  // between 0.8 and 0.88: hysteresis
  EXPECT_TRUE(g.zoneBusy(0));
  g.updateZones(1, zoneAt(0, 0.87), kStepS);  // just below the leave share
  EXPECT_TRUE(g.zoneBusy(0));
  g.updateZones(1, zoneAt(0, 0.9), kStepS);
  EXPECT_FALSE(g.zoneBusy(0));
  g.updateZones(1, zoneAt(0, 0.85), kStepS);  // free, and back in the band: stays free
  EXPECT_FALSE(g.zoneBusy(0));
  g.updateZones(1, zoneAt(0, 0.79), kStepS);
  EXPECT_TRUE(g.zoneBusy(0));
}

TEST(GuardZones, ALeaveShareBelowTheEnterShareIsTheEnterShare) {
  GuardOptions o = instantZones();
  o.busy_leave_share = 0.5;  // below busy_speed_share 0.8
  AdviceGuard g(o);
  g.updateZones(1, zoneAt(0, 0.6), kStepS);
  ASSERT_TRUE(g.zoneBusy(0));
  g.updateZones(1, zoneAt(0, 0.7), kStepS);
  EXPECT_TRUE(g.zoneBusy(0)) << "left below the share that makes it busy";
  g.updateZones(1, zoneAt(0, 0.81), kStepS);
  EXPECT_FALSE(g.zoneBusy(0));
}

TEST(GuardZones, BusyAtStartHoldsEveryZoneUntilItHasShownFreeRunning) {
  GuardOptions o;
  o.busy_at_start = true;
  o.busy_window_s = 1.0;  // ten steps
  AdviceGuard g(o);
  g.updateZones(2, {}, kStepS);
  EXPECT_TRUE(g.zoneBusy(0));
  EXPECT_TRUE(g.zoneBusy(1));
  EXPECT_DOUBLE_EQ(g.zoneSpeedShare(0), 0.0);
  int steps = 0;
  while (g.zoneBusy(0) && steps < 1000) {
    g.updateZones(2, zoneAt(0, 1.0), kStepS);
    ++steps;
  }
  // From 0 towards 1 at 1/10 a step: above 0.88 after ln(0.12) / ln(0.9), about 20 steps.
  EXPECT_GE(steps, 15);
  EXPECT_LE(steps, 25);
  EXPECT_TRUE(g.zoneBusy(1)) << "an empty zone showed no free running";
}

TEST(GuardZones, WithoutBusyAtStartAnEmptyRoadStartsFree) {
  AdviceGuard g{GuardOptions{}};
  g.updateZones(2, {}, kStepS);
  EXPECT_FALSE(g.zoneBusy(0));
  EXPECT_DOUBLE_EQ(g.zoneSpeedShare(0), 1.0);
}

TEST(GuardZones, SamplesOutsideTheZonesOrWithoutATopSpeedAreIgnored) {
  AdviceGuard g(instantZones());
  std::vector<ZoneSpeedSample> s{{-1, 0.0, kTopMps}, {2, 0.0, kTopMps}, {0, 0.0, 0.0}, {0, 50.0, kTopMps}};
  g.updateZones(2, s, kStepS);
  EXPECT_DOUBLE_EQ(g.zoneSpeedShare(0), 1.0);  // faster than its top speed counts as 1
  EXPECT_FALSE(g.zoneBusy(0));
  EXPECT_FALSE(g.zoneBusy(-1));
  EXPECT_FALSE(g.zoneBusy(2));
  EXPECT_DOUBLE_EQ(g.zoneSpeedShare(2), 1.0);
}

TEST(GuardZones, OffWhenTheBusyShareIsZeroOrTheGuardIsDisabled) {
  GuardOptions zero = instantZones();
  zero.busy_speed_share = 0.0;
  GuardOptions disabled = instantZones();
  disabled.enabled = false;
  disabled.busy_at_start = true;
  for (const GuardOptions& o : {zero, disabled}) {
    AdviceGuard g(o);
    EXPECT_FALSE(g.busyZonesOn());
    g.updateZones(2, zoneAt(0, 0.0), kStepS);
    EXPECT_FALSE(g.zoneBusy(0));
    EXPECT_DOUBLE_EQ(g.zoneSpeedShare(0), 1.0);
    EXPECT_EQ(g.counters().zone_steps, 0u);
  }
}

// --- The floor ---

TEST(GuardFloor, ShareOfTheAllowedSpeedOrOfTheTopSpeedIfLower) {
  AdviceGuard g(instantZones());  // floor 0.6
  EXPECT_DOUBLE_EQ(g.floorMps(cav(10.0, 0, 30.0)), 18.0);
  EXPECT_DOUBLE_EQ(g.floorMps(cav(10.0, 0, 50.0)), 24.0);  // its top speed 40 is lower
}

TEST(GuardFloor, ABusyZoneHasItsOwnShare) {
  AdviceGuard g = withBusyZone0();  // busy floor 1.0
  EXPECT_DOUBLE_EQ(g.floorShare(0), 1.0);
  EXPECT_DOUBLE_EQ(g.floorShare(1), 0.6);
  EXPECT_DOUBLE_EQ(g.floorMps(cav(10.0, 0)), 30.0);
}

TEST(GuardFloor, OffAsksNoAllowedSpeed) {
  GuardOptions o;
  o.floor_speed_share = 0.0;
  AdviceGuard g(o);
  int asked = 0;
  GuardCav c = cav(10.0);
  c.allowed_speed_mps = [&asked] { return ++asked, 30.0; };
  EXPECT_FALSE(g.floorOn());
  EXPECT_DOUBLE_EQ(g.floorMps(c), 0.0);
  EXPECT_FALSE(g.liftAdvisedChangeBound(c));
  EXPECT_EQ(asked, 0);
}

TEST(GuardFloor, HeldAccelerationStopsAtTheFloor) {
  AdviceGuard g{GuardOptions{}};  // floor 18 m/s
  HeldAcceleration h = g.holdAcceleration(cav(25.0), 2.0, kStepS);
  EXPECT_EQ(h.kind, HeldAcceleration::Kind::kCommand);
  EXPECT_DOUBLE_EQ(h.target_mps, 25.2);
  h = g.holdAcceleration(cav(18.1), -4.0, kStepS);  // would go to 17.7
  EXPECT_EQ(h.kind, HeldAcceleration::Kind::kFloored);
  EXPECT_DOUBLE_EQ(h.target_mps, 18.0);
  h = g.holdAcceleration(cav(18.0), 0.0, kStepS);  // at the floor: the command itself
  EXPECT_EQ(h.kind, HeldAcceleration::Kind::kCommand);
  EXPECT_EQ(g.counters().accelerate_steps, 3u);
  EXPECT_EQ(g.counters().accelerate_floored_steps, 1u);
}

TEST(GuardFloor, BelowTheFloorACavDrivesItself) {
  AdviceGuard g{GuardOptions{}};
  const HeldAcceleration h = g.holdAcceleration(cav(5.0), 0.5, kStepS);  // queued
  EXPECT_EQ(h.kind, HeldAcceleration::Kind::kReleased);
  EXPECT_EQ(g.counters().accelerate_released_steps, 1u);
}

TEST(GuardFloor, WithAccelerationAdviceOffEveryAccelerateIsTheCavsOwnDriving) {
  GuardOptions o;
  o.accelerate_advice = false;
  AdviceGuard g(o);
  for (double accel : {2.0, 0.0, -4.0}) {  // above, at and below the floor's reach
    const HeldAcceleration h = g.holdAcceleration(cav(25.0), accel, kStepS);
    EXPECT_EQ(h.kind, HeldAcceleration::Kind::kReleased) << accel;
  }
  EXPECT_EQ(g.counters().accelerate_steps, 3u);
  EXPECT_EQ(g.counters().accelerate_own_driving_steps, 3u);
  EXPECT_EQ(g.counters().accelerate_floored_steps, 0u);
  EXPECT_EQ(g.counters().accelerate_released_steps, 0u);
  // Lane changes are judged as before: the option touches accelerations only.
  AdviceCase change;
  change.lane_change = true;
  change.time_s = 100.0;
  EXPECT_EQ(g.judgeAdvice(change, GuardMemory{}), AdviceVerdict::kCarryOut);
  // With the guard off no rule acts, this one included (the paper).
  o.enabled = false;
  AdviceGuard off(o);
  EXPECT_EQ(off.holdAcceleration(cav(25.0), 2.0, kStepS).kind, HeldAcceleration::Kind::kCommand);
}

TEST(GuardFloor, WithoutAFloorTheCommandReachesTheCarNeverBelowStandstill) {
  GuardOptions o;
  o.enabled = false;
  AdviceGuard g(o);
  HeldAcceleration h = g.holdAcceleration(cav(5.0), -4.5, kStepS);
  EXPECT_EQ(h.kind, HeldAcceleration::Kind::kCommand);
  EXPECT_DOUBLE_EQ(h.target_mps, 4.55);
  h = g.holdAcceleration(cav(0.2), -4.5, kStepS);
  EXPECT_DOUBLE_EQ(h.target_mps, 0.0);
}

TEST(GuardFloor, AnAdvisedChangesBoundIsLiftedBelowTheFloor) {
  AdviceGuard g{GuardOptions{}};
  EXPECT_FALSE(g.liftAdvisedChangeBound(cav(25.0)));
  EXPECT_TRUE(g.liftAdvisedChangeBound(cav(10.0)));
  EXPECT_EQ(g.counters().lane_change_steps, 2u);
  EXPECT_EQ(g.counters().lane_change_released_steps, 1u);
}

// --- Advice ---

TEST(GuardAdvice, AHandedBackCavsAdviceIsDropped) {
  AdviceGuard g{GuardOptions{}};
  GuardMemory m;
  m.handed_back = true;
  AdviceCase keep;
  EXPECT_EQ(g.judgeAdvice(keep, m), AdviceVerdict::kDropHandedBack);
  EXPECT_EQ(g.judgeAdvice(laneChange(1), m), AdviceVerdict::kDropHandedBack);
  EXPECT_EQ(g.counters().handback_advice_dropped, 2u);
  EXPECT_EQ(g.counters().lane_changes_advised, 0u);
}

TEST(GuardAdvice, InAssistModeABusyZoneCanKeepItsAdvice) {
  GuardOptions keep_advice;
  keep_advice.busy_assist_advice = true;
  AdviceGuard g{keep_advice};
  AdviceCase accelerate;
  GuardMemory assist, advisory;
  g.recordHandback(assist, true, true);
  g.recordHandback(advisory, true, false);
  EXPECT_TRUE(assist.handed_back);  // still counted as handed back: its gaps and change bound
  EXPECT_FALSE(AdviceGuard::drivesItself(assist));
  EXPECT_TRUE(AdviceGuard::drivesItself(advisory));  // advisory mode: the hand-back as ever
  EXPECT_EQ(g.judgeAdvice(accelerate, assist), AdviceVerdict::kCarryOut);
  EXPECT_EQ(g.judgeAdvice(accelerate, advisory), AdviceVerdict::kDropHandedBack);
  g.recordHandback(assist, false, true);
  EXPECT_FALSE(assist.advice_kept);
  AdviceGuard plain{GuardOptions{}};  // off (the default): dropped in assist mode too
  GuardMemory m;
  plain.recordHandback(m, true, true);
  EXPECT_TRUE(AdviceGuard::drivesItself(m));
  EXPECT_EQ(plain.judgeAdvice(accelerate, m), AdviceVerdict::kDropHandedBack);
}

TEST(GuardAdvice, SpeedAdviceIsCarriedOutAndNotCountedAsAChange) {
  AdviceGuard g = withBusyZone0();
  AdviceCase accelerate;
  accelerate.zone = 0;
  EXPECT_EQ(g.judgeAdvice(accelerate, GuardMemory{}), AdviceVerdict::kCarryOut);
  EXPECT_EQ(g.counters().lane_changes_advised, 0u);
}

TEST(GuardAdvice, WeavingInABusyZoneIsRefusedARouteChangeIsNot) {
  AdviceGuard g = withBusyZone0();
  EXPECT_EQ(g.judgeAdvice(laneChange(0), GuardMemory{}), AdviceVerdict::kRefuseBusy);
  EXPECT_EQ(g.judgeAdvice(laneChange(1), GuardMemory{}), AdviceVerdict::kCarryOut);
  AdviceCase exit = laneChange(0);
  exit.serves_route = true;
  EXPECT_EQ(g.judgeAdvice(exit, GuardMemory{}), AdviceVerdict::kCarryOut);
  AdviceCase under_way = laneChange(0);
  under_way.change_under_way = true;
  EXPECT_EQ(g.judgeAdvice(under_way, GuardMemory{}), AdviceVerdict::kCarryOut);
  EXPECT_EQ(g.counters().lane_changes_advised, 4u);
  EXPECT_EQ(g.counters().lane_changes_busy_refused, 1u);
}

TEST(GuardAdvice, WeavingSoonAfterAChangeIsRefusedForTheCooldown) {
  GuardOptions o;
  o.lane_change_cooldown_s = 10.0;
  AdviceGuard g(o);
  GuardMemory m;
  AdviceGuard::laneChangeMade(m, 100.0);
  EXPECT_EQ(g.judgeAdvice(laneChange(1, 109.9), m), AdviceVerdict::kRefuseCooldown);
  AdviceCase exit = laneChange(1, 105.0);
  exit.serves_route = true;
  EXPECT_EQ(g.judgeAdvice(exit, m), AdviceVerdict::kCarryOut);
  EXPECT_EQ(g.judgeAdvice(laneChange(1, 110.0), m), AdviceVerdict::kCarryOut);
  EXPECT_EQ(g.counters().lane_changes_cooled_down, 1u);
}

TEST(GuardAdvice, ABusyZoneCountsBeforeTheCooldown) {
  GuardOptions o = instantZones();
  o.lane_change_cooldown_s = 10.0;
  AdviceGuard g = withBusyZone0(o);
  GuardMemory m;
  AdviceGuard::laneChangeMade(m, 100.0);
  EXPECT_EQ(g.judgeAdvice(laneChange(0, 101.0), m), AdviceVerdict::kRefuseBusy);
  EXPECT_EQ(g.counters().lane_changes_busy_refused, 1u);
  EXPECT_EQ(g.counters().lane_changes_cooled_down, 0u);
}

TEST(GuardAdvice, NoNewChangeWhereTrafficIsInserted) {
  AdviceGuard g{GuardOptions{}};
  AdviceCase a = laneChange(0);
  a.on_insertion_edge = true;
  a.serves_route = true;  // whatever it serves
  EXPECT_EQ(g.judgeAdvice(a, GuardMemory{}), AdviceVerdict::kRefuseInsertionEdge);
  a.change_under_way = true;  // one already being made goes on
  EXPECT_EQ(g.judgeAdvice(a, GuardMemory{}), AdviceVerdict::kCarryOut);
  EXPECT_EQ(g.counters().lane_changes_insertion_refused, 1u);

  GuardOptions off;
  off.insertion_edge = false;
  AdviceGuard g_off(off);
  a.change_under_way = false;
  EXPECT_EQ(g_off.judgeAdvice(a, GuardMemory{}), AdviceVerdict::kCarryOut);
}

TEST(GuardAdvice, ADisabledGuardCarriesEveryChangeOut) {
  GuardOptions o = instantZones();
  o.enabled = false;
  o.lane_change_cooldown_s = 10.0;
  AdviceGuard g = withBusyZone0(o);
  GuardMemory m;
  AdviceGuard::laneChangeMade(m, 100.0);
  AdviceCase a = laneChange(0, 101.0);
  a.on_insertion_edge = true;
  EXPECT_EQ(g.judgeAdvice(a, m), AdviceVerdict::kCarryOut);
  EXPECT_EQ(g.counters().lane_changes_advised, 1u);
  EXPECT_DOUBLE_EQ(g.floorShare(0), 0.0);
  EXPECT_DOUBLE_EQ(g.busyLcAssertive(), 0.0);
}

// --- Hand-back ---

TEST(GuardHandback, ACavOnTheMainlineOfABusyZoneIsHandedBack) {
  AdviceGuard g = withBusyZone0();
  EXPECT_TRUE(g.wantsHandback(cav(5.0, 0), false, true, true));
  EXPECT_FALSE(g.wantsHandback(cav(5.0, 1), false, true, true));   // free zone
  EXPECT_FALSE(g.wantsHandback(cav(5.0, 0), true, true, true));    // merging by itself
  EXPECT_FALSE(g.wantsHandback(cav(5.0, 0), false, false, true));  // on a junction
  EXPECT_FALSE(g.wantsHandback(cav(5.0, 0), false, true, false));  // on a ramp
  EXPECT_FALSE(g.wantsHandback(cav(5.0, -1), false, true, true));  // outside the zones
  GuardOptions off = instantZones();
  off.busy_handback = false;
  EXPECT_FALSE(withBusyZone0(off).wantsHandback(cav(5.0, 0), false, true, true));
}

TEST(GuardHandback, ChangesOnlyWhenWantedAndRemembered) {
  AdviceGuard g{GuardOptions{}};
  GuardMemory m;
  EXPECT_EQ(AdviceGuard::handbackChange(false, m), HandbackChange::kNone);
  EXPECT_EQ(AdviceGuard::handbackChange(true, m), HandbackChange::kHandBack);
  g.recordHandback(m, true);
  EXPECT_TRUE(m.handed_back);
  EXPECT_EQ(AdviceGuard::handbackChange(true, m), HandbackChange::kNone);
  EXPECT_EQ(AdviceGuard::handbackChange(false, m), HandbackChange::kTakeBack);
  g.countCavStep(m);
  g.recordHandback(m, false);
  g.countCavStep(m);
  EXPECT_FALSE(m.handed_back);
  EXPECT_EQ(g.counters().handbacks, 1u);
  EXPECT_EQ(g.counters().handback_steps, 1u);
}

TEST(GuardHandback, ABusyZoneSetsItsGapAcceptance) {
  GuardOptions o;
  o.busy_lc_assertive = 2.5;
  EXPECT_DOUBLE_EQ(AdviceGuard(o).busyLcAssertive(), 2.5);
  o.busy_lc_assertive = 0.0;
  EXPECT_DOUBLE_EQ(AdviceGuard(o).busyLcAssertive(), 0.0);
}

// --- The busy zones' change bound ---

GuardMemory handedBack() {
  GuardMemory m;
  m.handed_back = true;
  return m;
}

TEST(GuardChangeBound, HoldsFromTheChangeUntilTheHoldIsOver) {
  AdviceGuard g{GuardOptions{}};  // 1.47 for 4 s
  GuardMemory m = handedBack();
  EXPECT_DOUBLE_EQ(g.busyChangeBound(cav(25.0), false, 0.0, false, 10.0, m), 0.0);  // no change yet
  EXPECT_DOUBLE_EQ(g.busyChangeBound(cav(25.0), true, 0.0, false, 10.0, m), 1.47);
  g.recordBusyChangeBound(m, true);
  EXPECT_DOUBLE_EQ(g.busyChangeBound(cav(25.0), false, 0.0, false, 13.9, m), 1.47);
  g.recordBusyChangeBound(m, true);
  EXPECT_DOUBLE_EQ(g.busyChangeBound(cav(25.0), false, 0.0, false, 14.0, m), 0.0);
  g.recordBusyChangeBound(m, false);
  EXPECT_FALSE(m.busy_change_bounded);
  EXPECT_EQ(g.counters().busy_change_bounds, 1u);
  EXPECT_EQ(g.counters().busy_change_bound_steps, 2u);
}

TEST(GuardChangeBound, MovingSidewaysFastStartsItAndRestartsTheHold) {
  AdviceGuard g{GuardOptions{}};
  GuardMemory m = handedBack();
  EXPECT_DOUBLE_EQ(g.busyChangeBound(cav(25.0), false, 0.3, false, 10.0, m), 0.0);  // alignment
  EXPECT_DOUBLE_EQ(g.busyChangeBound(cav(25.0), false, -0.5, false, 10.0, m), 1.47);
  EXPECT_DOUBLE_EQ(g.busyChangeBound(cav(25.0), false, 0.5, false, 13.0, m), 1.47);
  EXPECT_DOUBLE_EQ(m.busy_change_until_s, 17.0);
}

TEST(GuardChangeBound, NotForACavNotHandedBackNorUnderAnAdvisedChangesBound) {
  AdviceGuard g{GuardOptions{}};
  GuardMemory own;
  EXPECT_DOUBLE_EQ(g.busyChangeBound(cav(25.0), true, 1.0, false, 10.0, own), 0.0);
  EXPECT_LT(own.busy_change_until_s, 0.0);
  GuardMemory m = handedBack();
  EXPECT_DOUBLE_EQ(g.busyChangeBound(cav(25.0), true, 1.0, true, 10.0, m), 0.0);
}

TEST(GuardChangeBound, NotBelowTheFreeZonesFloor) {
  AdviceGuard g = withBusyZone0();  // zone 0's own floor would be the allowed speed
  GuardMemory m = handedBack();
  EXPECT_DOUBLE_EQ(g.busyChangeBound(cav(17.9, 0), true, 0.0, false, 10.0, m), 0.0);  // 0.6 x 30
  EXPECT_DOUBLE_EQ(g.busyChangeBound(cav(18.0, 0), true, 0.0, false, 10.0, m), 1.47);
}

TEST(GuardChangeBound, OffAtZeroOrDisabled) {
  GuardOptions zero;
  zero.busy_change_max_accel_mps2 = 0.0;
  GuardOptions disabled;
  disabled.enabled = false;
  for (const GuardOptions& o : {zero, disabled}) {
    GuardMemory m = handedBack();
    EXPECT_DOUBLE_EQ(AdviceGuard(o).busyChangeBound(cav(25.0), true, 1.0, false, 10.0, m), 0.0);
    EXPECT_LT(m.busy_change_until_s, 0.0);
  }
}

}  // namespace
