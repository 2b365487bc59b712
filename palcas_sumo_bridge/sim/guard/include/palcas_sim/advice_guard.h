#pragma once
// The advice guard's decisions: what of the RSUs' advice a CAV carries out, which zones are
// busy, when a CAV is handed back to its own driving and how it changes lanes there. Pure
// decisions of the state they are given (no SUMO, no ROS): SumoSession reads that state from
// SUMO and applies what the guard decides. What each option means: config/bridge.yaml, the
// key of the same name with the prefix guard_.

#include <cstdint>
#include <functional>
#include <vector>

namespace palcas::sim {

/// The guard's options: one field per key guard_<name> of config/bridge.yaml (documented
/// there), same defaults.
struct GuardOptions {
  bool enabled = true;  ///< false: no rule acts (the paper: advice always reaches the car)
  double floor_speed_share = 0.6;
  double lane_change_cooldown_s = 0.0;
  double busy_speed_share = 0.8;
  double busy_leave_share = 0.88;
  double busy_window_s = 30.0;
  bool busy_at_start = false;
  double busy_floor_speed_share = 1.0;
  bool busy_handback = true;
  bool busy_assist_advice = false;  ///< assist mode: a busy zone's CAVs keep their advice
  double busy_lc_assertive = 2.0;
  double busy_change_max_accel_mps2 = 1.47;
  double busy_change_hold_s = 4.0;
  bool insertion_edge = true;
  /// false: an ACCELERATE advisory is carried out as the CAV's own car following (as under
  /// KEEP), so the learned advice reaches the car as lane changes only. true: the paper.
  bool accelerate_advice = true;
};

/// How often the advice guard acted, in CAV steps.
struct GuardCounters {
  std::uint64_t accelerate_steps = 0;         ///< CAV steps under an ACCELERATE command
  std::uint64_t accelerate_floored_steps = 0; ///< ... held at the floor instead of the command
  std::uint64_t accelerate_released_steps = 0;///< ... driven by its own model (below the floor)
  std::uint64_t accelerate_own_driving_steps = 0;///< ... driven by its own model (accelerate_advice off)
  std::uint64_t lane_change_steps = 0;        ///< CAV steps with an advised change under way
  std::uint64_t lane_change_released_steps = 0;///< ... with the acceleration bound lifted
  std::uint64_t lane_changes_advised = 0;       ///< advised changes received
  std::uint64_t lane_changes_cooled_down = 0;   ///< ... not carried out (cooldown)
  std::uint64_t lane_changes_busy_refused = 0;  ///< ... not carried out (busy zone)
  std::uint64_t lane_changes_insertion_refused = 0;  ///< ... not carried out (insertion edge)
  std::uint64_t busy_zone_steps = 0;            ///< zone steps a zone was busy (all zones)
  std::uint64_t handbacks = 0;                  ///< CAVs handed back to their own driving
  std::uint64_t handback_steps = 0;             ///< CAV steps spent handed back
  std::uint64_t handback_advice_dropped = 0;    ///< advisories not carried out (handed back)
  std::uint64_t busy_change_bounds = 0;         ///< own changes in a busy zone whose accel was bounded
  std::uint64_t busy_change_bound_steps = 0;    ///< CAV steps under that bound
  std::uint64_t zone_steps = 0;                 ///< zone steps in all (zones x steps)
  // Which guard, if any, had a hand on a CAV when it collided (a CAV can count in several).
  std::uint64_t collided_cavs = 0;                 ///< CAVs removed after a collision
  std::uint64_t collided_handed_back = 0;          ///< ... handed back to their own driving
  std::uint64_t collided_busy_change_bounded = 0;  ///< ... under the busy zones' change bound
  std::uint64_t collided_advised_change = 0;       ///< ... with an advised lane change under way
  std::uint64_t collided_accelerate = 0;          ///< ... holding an ACCELERATE advisory
};

/// What the guard remembers of one CAV from step to step.
struct GuardMemory {
  bool handed_back = false;            ///< busy zone: its own route-aware driving, advice dropped
  bool advice_kept = false;            ///< handed back in assist mode with busy_assist_advice: advised still
  double last_lane_change_s = -1e18;   ///< when its last advised change was made (cooldown)
  double busy_change_until_s = -1e18;  ///< end of the busy zones' change bound
  bool busy_change_bounded = false;    ///< that bound is in force
};

/// One CAV as the guard sees it in this step.
struct GuardCav {
  double speed_mps = 0.0;
  double top_speed_mps = 0.0;  ///< its own largest speed
  int zone = -1;               ///< RSU zone it is in (RoadLayout::zoneAt), -1 = none
  /// Its lane's speed limit for it [m/s]: asked only when a floor is needed (a SUMO call).
  std::function<double()> allowed_speed_mps;
};

/// One mainline vehicle's speed for its zone's speed share.
struct ZoneSpeedSample {
  int zone = -1;
  double speed_mps = 0.0;
  double top_speed_mps = 0.0;
};

/// What becomes of an advisory the CAV received.
enum class AdviceVerdict {
  kCarryOut,
  kDropHandedBack,       ///< it drives itself (busy zone): no advice is carried out
  kRefuseInsertionEdge,  ///< a lane change where SUMO inserts traffic
  kRefuseCooldown,       ///< weaving moments after its last advised change
  kRefuseBusy,           ///< weaving in a busy zone
};

/// An advisory as the guard judges it.
struct AdviceCase {
  bool lane_change = false;       ///< LEFT or RIGHT (else ACCELERATE or KEEP)
  bool serves_route = false;      ///< a RIGHT towards its exit, a LEFT off the acceleration lane
  bool change_under_way = false;  ///< an advised change is still being made
  bool on_insertion_edge = false; ///< on the mainline edge where SUMO inserts traffic
  int zone = -1;
  double time_s = 0.0;
};

/// A held ACCELERATE for one step: the speed to aim at, or its own driving.
struct HeldAcceleration {
  enum class Kind { kCommand, kFloored, kReleased } kind = Kind::kCommand;
  double target_mps = 0.0;  ///< the speed to set (kCommand, kFloored)
};

/// A hand-back to carry out: the CAV's zone turned busy (kHandBack) or free (kTakeBack).
enum class HandbackChange { kNone, kHandBack, kTakeBack };

class AdviceGuard {
 public:
  explicit AdviceGuard(const GuardOptions& options = {}) : options_(options) {}

  const GuardOptions& options() const { return options_; }
  const GuardCounters& counters() const { return counters_; }
  GuardCounters& counters() { return counters_; }

  bool floorOn() const { return options_.enabled && options_.floor_speed_share > 0.0; }
  bool busyZonesOn() const { return options_.enabled && options_.busy_speed_share > 0.0; }

  // Zones.
  /// One step of the zones' smoothed speed shares and their busy state, from the mainline
  /// vehicles' speeds (samples outside [0, zones) or without a top speed are ignored):
  /// busy when the share falls below busy_speed_share, free again above busy_leave_share.
  /// Does nothing while busy zones are off.
  void updateZones(int zones, const std::vector<ZoneSpeedSample>& samples, double step_s);
  /// Whether zone k is busy now (false outside the zones and while busy zones are off).
  bool zoneBusy(int zone) const;
  /// Zone k's smoothed speed share (1 outside the zones and while busy zones are off).
  double zoneSpeedShare(int zone) const;

  // The floor.
  /// The floor's share for a CAV in `zone` (the busy zones' own there); 0 = no floor.
  double floorShare(int zone) const;
  /// share x the CAV's allowed speed (its lane's limit, or its top speed if lower); 0 if share <= 0.
  static double floorMps(const GuardCav& cav, double share);
  double floorMps(const GuardCav& cav) const { return floorMps(cav, floorShare(cav.zone)); }

  // Advice.
  /// What becomes of an advisory (counted). `memory`: the CAV's.
  AdviceVerdict judgeAdvice(const AdviceCase& advice, const GuardMemory& memory);
  /// An advised change was made in its target lane at `time_s` (for the cooldown).
  static void laneChangeMade(GuardMemory& memory, double time_s) { memory.last_lane_change_s = time_s; }
  /// One step of a held ACCELERATE (counted): never below the floor, or, below it already,
  /// its own driving; always its own driving with accelerate_advice off.
  HeldAcceleration holdAcceleration(const GuardCav& cav, double accel_mps2, double step_s);
  /// One step of an advised change under way (counted): true when its acceleration bound is
  /// lifted (the CAV is below the floor: queued or slowed, it gets going at its own rate).
  bool liftAdvisedChangeBound(const GuardCav& cav);

  // Busy zones' own driving.
  /// Whether a CAV is to be handed back: busy_handback on and it is on the road's mainline or
  /// acceleration lane in a busy zone, not merging by itself.
  bool wantsHandback(const GuardCav& cav, bool merge_mode, bool on_road, bool mainline_or_accel_lane) const;
  /// What to carry out for a CAV that `wants` to be handed back, given its memory.
  static HandbackChange handbackChange(bool wants, const GuardMemory& memory);
  /// The hand-back (or taking back) was carried out (counted). In assist mode with
  /// busy_assist_advice the CAV keeps its advice (advice_kept): it still gets the busy zone's
  /// gap acceptance and change bound, and the RSU still advises it.
  void recordHandback(GuardMemory& memory, bool handed_back, bool assist_mode = false);
  /// It drives itself and is not advised: handed back, its advice not kept.
  static bool drivesItself(const GuardMemory& memory) { return memory.handed_back && !memory.advice_kept; }
  /// lcAssertive for a CAV making its own changes in a busy zone; 0 = leave its own.
  double busyLcAssertive() const { return options_.enabled ? options_.busy_lc_assertive : 0.0; }
  /// The busy zones' change bound [m/s^2] for this step: from when a handed-back CAV moves
  /// sideways (`switched`: into another lane or road part; or a fast lateral speed) until
  /// busy_change_hold_s after; not while an advised change bounds it, nor below the free
  /// zones' floor. 0 = no bound. Updates memory.busy_change_until_s.
  double busyChangeBound(const GuardCav& cav, bool switched, double lateral_speed_mps,
                         bool advised_change_bounded, double time_s, GuardMemory& memory) const;
  /// The busy zones' change bound is in force (on) or not after this step (counted).
  void recordBusyChangeBound(GuardMemory& memory, bool on);
  /// Counts one CAV step (its time handed back).
  void countCavStep(const GuardMemory& memory);

 private:
  GuardOptions options_;
  GuardCounters counters_;
  /// Per zone: smoothed speed share of its mainline vehicles, and whether it is busy.
  std::vector<double> zone_speed_share_;
  std::vector<bool> zone_busy_;
};

}  // namespace palcas::sim
