#pragma once
// SumoSession: one running SUMO simulation seen the way PALCAS needs it. It starts SUMO
// (in-process through libsumo, or an external sumo/sumo-gui through libtraci: the same
// source is compiled once per API), reads every vehicle with subscriptions each step,
// applies advisories to CAVs and handles exits. No ROS in here.

#include <cstdint>
#include <memory>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "palcas_core/common/action.h"
#include "palcas_core/common/road_terms.h"
#include "palcas_core/metrics/advisory_validator.h"
#include "palcas_sim/advice_guard.h"
#include "palcas_sim/own_road.h"
#include "palcas_sim/road_layout.h"
#include "palcas_sim/roadside.h"

namespace palcas::sim {

/// Longitudinal command a CAV holds between advisories.
enum class HeldCommand { kNone, kKeepSpeed, kAccelerate };

struct SessionOptions {
  std::vector<std::string> sumo_args;  ///< arguments after the binary, e.g. {"-c", "x.sumocfg"}
  std::string sumo_binary = "sumo";    ///< libtraci only: "sumo" or "sumo-gui"
  int traci_port = -1;                 ///< libtraci only: -1 = let SUMO choose
  /// libtraci only: SUMO runs as a process of its own session that nobody waits for, and the
  /// session connects to it by port (libtraci's start() waits for the process it started as
  /// it closes, so a sumo-gui that stays open at the end would hold the bridge forever).
  bool detach_sumo = false;
  double cluster_length_m = 800.0;
  /// A user's own road (scenario network_file): the .net.xml SUMO runs, in which the road is
  /// found by discoverOwnRoad with own_road (cluster_length_m is then the mainline length /
  /// own_road.clusters). "" = a road of the naming convention, read from SUMO by its names.
  std::string own_road_net_file;
  OwnRoadOptions own_road;
  /// true: CAVs follow advisories (RSU arms); false: SUMO drives every vehicle (SUMO-native).
  bool advisory_control = false;
  /// SUMO speed-mode bits for CAVs under advisory control (31 = SUMO keeps its safe-speed,
  /// acceleration and right-of-way checks; 30 lets advisories override the safe speed).
  int cav_speed_mode = 31;
  /// SUMO lane-change-mode bits for CAVs under advisory control. 1536 = no strategic,
  /// cooperative, speed-gain or keep-right changes of its own (so only advisories change
  /// lanes and a CAV can miss its exit); advised changes respect the others' gaps; SL2015
  /// keeps its lateral alignment. 256 (the paper's reading): immediate collisions only.
  int cav_lane_change_mode = 1536;
  double lane_change_duration_s = 2.0;  ///< an advised lane change not done by then is dropped
  /// true: a CAV's own car-following model (SUMO's) drives it longitudinally whenever no
  /// ACCELERATE command holds: with no advisory, under KEEP, during an advised lane change
  /// and when a command expires. false (the paper's literal a3 "maintain the current
  /// cruising speed"): KEEP and lane changes freeze the current speed until the next command.
  bool own_car_following = true;
  /// true: a CAV on an acceleration lane may make SUMO's strategic change onto the mainline
  /// by itself (bit 0 of the lane-change mode, only while on that lane): finishing a merge
  /// is part of its own automation. false: only an advised LEFT merges it.
  bool own_merge = true;
  /// Largest |acceleration| an ACCELERATE advisory may command [m/s^2]; larger requests are
  /// clipped to it. 0 = no limit (the paper: the action range [-4.5, 2.6] reaches the car).
  /// Emergency braking stays with the car-following model underneath (cav_speed_mode 31).
  double max_advised_accel_mps2 = 1.47;
  /// true: colliding vehicles are removed by the session through Vehicle::remove right after
  /// the step, SUMO itself only reporting them (the session adds --collision.action warn). SUMO 1.15's own removal (collision.action remove) leaves a vehicle caught mid
  /// lane change registered on its neighbour lane: it aborts in getBackPositionOnLane or
  /// frees the vehicle twice (SIGSEGV in removePending), fixed only in SUMO 1.17.
  bool remove_collided = true;
  /// CAVs' largest acceleration / deceleration [m/s^2] (SUMO's accel / decel of the
  /// vehicle, set at insertion in every arm, advisory control or not); 0 = their vType's
  /// own (2.6 / 4.5). An automated vehicle tuned for comfort; emergency braking beyond decel
  /// stays possible (SUMO's emergencyDecel).
  double cav_max_accel_mps2 = 0.0;
  double cav_max_decel_mps2 = 0.0;
  /// A CAV's largest acceleration / deceleration while an advised lane change is under way
  /// [m/s^2] (SUMO's accel / decel of the vehicle, restored when the change is done or
  /// dropped); 0 = its own. The lane-change model speeds up or brakes to make the gap it was
  /// asked to take, at up to the vehicle's limits. SUMO's car following also plans its safe
  /// gap with decel, so a small decel bound makes the CAV drop far back while it changes.
  double lane_change_max_accel_mps2 = 0.0;
  double lane_change_max_decel_mps2 = 0.0;
  /// The advice guard (advice_guard.h): what of the advice a CAV carries out, busy zones and
  /// their hand-back. Its keys and what they mean: config/bridge.yaml, guard_*.
  GuardOptions guard;
  /// Assist mode (arm palcas_assist): CAVs keep their own route-aware driving, as a road
  /// operator's fleet would: their route runs to their off-ramp from the start and SUMO's
  /// lane-change model makes its own strategic, cooperative and speed-gain changes
  /// (assist_lane_change_mode); advisories ride on top (an advised change is a TraCI request,
  /// which wins over the CAV's own changes for its lane_change_duration_s). false: only
  /// advisories change lanes and the RSUs alone serve the exits (cav_lane_change_mode).
  bool assist_mode = false;
  /// SUMO lane-change-mode bits for CAVs in assist mode (1621 = SUMO's default: every change
  /// of its own unless a TraCI request conflicts, requests respect the others' gaps, sublane
  /// alignment).
  int assist_lane_change_mode = 1621;
};

/// One vehicle on the road, updated every step.
struct VehicleRecord {
  // Fixed at departure.
  std::string id;
  std::string type_id;
  std::string route_id;
  bool is_cav = false;
  RouteKind route_kind = RouteKind::kMainThrough;
  int entry_cluster = -1;  ///< cluster of its on-ramp, -1 = mainline start
  int exit_cluster = -1;   ///< cluster of its off-ramp, -1 = no exit
  double length_m = 0.0;
  double width_m = 0.0;
  double max_speed_mps = 0.0;
  // Read every step.
  std::string edge;
  int sumo_lane_index = -1;
  int lane = 0;            ///< paper lane, 0 = not on a mainline lane
  RoadPart part = RoadPart::kUnknown;
  int part_cluster = -1;   ///< cluster of the ramp / merge edge it is on, else -1
  double x_m = 0.0;          ///< along the mainline (RoadLayout: SUMO's x, or measured along the lanes)
  double map_x_m = 0.0;      ///< x in SUMO's map frame (for drawing)
  double map_y_m = 0.0;      ///< y in SUMO's map frame (for drawing)
  double heading_rad = 0.0;  ///< driving direction in the map frame (from its last move), 0 = +x
  double lateral_m = 0.0;
  double speed_mps = 0.0;
  double accel_mps2 = 0.0;
  double lateral_speed_mps = 0.0;
  double lane_pos_m = 0.0;
  double distance_to_exit_m = 0.0;  ///< +inf without an exit or once it is behind
  bool on_accel_lane = false;
  double accel_lane_pos_m = 0.0;
  double accel_lane_length_m = 0.0;
  // Advisory control state.
  HeldCommand command = HeldCommand::kNone;
  double command_value = 0.0;  ///< held speed [m/s] or acceleration [m/s^2]
  bool exit_committed = false; ///< SUMO target switched to its off-ramp
  bool speed_overridden = false; ///< a setSpeed of ours is in force (else SUMO's own model)
  bool merge_mode = false;       ///< strategic lane changes allowed (own_merge, accel lane)
  GuardMemory guard;             ///< what the advice guard remembers of it
  std::string own_lc_assertive;  ///< its lcAssertive before a busy zone changed it (empty: unchanged)
  double busy_change_own_accel_mps2 = 0.0;  ///< its accel before the busy zones' change bound
  /// Advised lane change under way, in paper lanes: SUMO's request is per lane index of
  /// the current edge, so it is re-issued when the vehicle enters an edge whose indices
  /// differ (a merge edge), until the target lane is reached or the time is up.
  int lane_change_target = 0;       ///< paper lane, 0 = none
  double lane_change_until_s = 0.0; ///< simulation time the request expires
  std::string lane_change_edge;     ///< edge the request was last issued on
  /// The vehicle's own accel / decel while an advised change bounds them (restored after).
  bool lane_change_bounded = false;
  double own_accel_mps2 = 0.0, own_decel_mps2 = 0.0;
};

/// Counts a vehicle that collided in `g`'s collided_* counters (CAVs only), by the guard
/// states it was in during its last step: whether a guard was involved in a collision.
void countCollidedUnderGuard(const VehicleRecord& v, GuardCounters* g);

/// What happened during one step besides vehicles moving.
struct StepEvents {
  std::vector<std::string> departed;
  std::vector<std::string> arrived;     ///< left the network normally
  std::vector<std::string> collided;    ///< removed after a collision
  std::vector<std::string> teleported;  ///< started a teleport
  /// Records of vehicles that left this step (arrived, collided or teleported), as last seen.
  std::vector<VehicleRecord> removed;
};

/// What the validator knows of a vehicle (null: not on the road) with `num_lanes` mainline
/// lanes at its position (SumoSession::known gives the lanes of its edge).
metrics::KnownVehicle knownVehicle(const VehicleRecord* record, int num_lanes);

class SumoSession {
 public:
  /// Starts SUMO and reads the network. @throws std::runtime_error with SUMO's message
  /// when SUMO cannot start, or std::invalid_argument when the network breaks the naming
  /// convention of road_layout.h.
  explicit SumoSession(const SessionOptions& options);
  ~SumoSession();
  SumoSession(const SumoSession&) = delete;
  SumoSession& operator=(const SumoSession&) = delete;

  /// Applies held commands, advances SUMO by one step, reads every vehicle.
  const StepEvents& step();
  /// What the latest step() reported (empty before the first step).
  const StepEvents& lastEvents() const { return events_; }

  /// Simulation time [s] and step count since start.
  double timeS() const { return time_s_; }
  std::uint64_t stepCount() const { return step_count_; }
  double stepLengthS() const { return step_length_s_; }
  /// Vehicles still expected (on the road, waiting to depart or loaded later).
  int minExpectedVehicles() const;
  const RoadLayout& road() const { return *road_; }
  /// Centre lines (x, y) of every lane of the network, for drawing.
  const std::vector<std::vector<std::pair<double, double>>>& laneShapes() const {
    return lane_shapes_;
  }
  /// Where each zone's RSU stands in the map: beside the rightmost through lane at the zone's
  /// centre, RSU_SHOULDER_M off it (roadside.h), on any road.
  const std::vector<MapPose>& rsuPoses() const { return rsu_poses_; }
  const std::vector<VehicleRecord>& vehicles() const { return vehicles_; }
  /// nullptr when no such vehicle is on the road.
  const VehicleRecord* find(const std::string& id) const;

  /// What the advisory validator needs to know of vehicle `id` (exists = false when it is not
  /// on the road), its lane count the lanes its edge has: the trip's one lane check.
  metrics::KnownVehicle known(const std::string& id) const;
  /// Applies an advisory validateAdvisory accepted against known(id) (`action_code`: a
  /// palcas::Action code, as palcas_msgs/Advisory carries it) to a CAV, as the advice guard
  /// allows: lane changes go through SUMO's changeLane for lane_change_duration_s while the
  /// speed is held; ACCELERATE holds `accel_mps2`; KEEP holds the current speed. Returns the
  /// guard's verdict (kCarryOut: done as advised; otherwise declined, and why).
  /// @throws std::invalid_argument for an unknown vehicle, an unknown action code or a
  /// non-finite acceleration.
  AdviceVerdict applyAdvisory(const std::string& id, int action_code, double accel_mps2);
  /// The command of a controlled CAV ended (expired, or its RSU is late or lost): with
  /// own_car_following SUMO's model drives it again, else it keeps its current speed (not on
  /// an off-ramp, where SUMO drives it again). Unknown ids are ignored.
  void endCommand(const std::string& id);

  /// Advised lane changes finished in the target lane / dropped because they could not be
  /// made within lane_change_duration_s (the lane-change model found no safe gap).
  std::uint64_t laneChangesDone() const { return lane_changes_done_; }
  std::uint64_t laneChangesDropped() const { return lane_changes_dropped_; }
  /// Tracked vehicles SUMO no longer knew when a command was applied (forgotten, not fatal).
  std::uint64_t vanishedVehicles() const { return vanished_vehicles_; }
  /// Exit commitments / withdrawals SUMO refused (the vehicle kept its route).
  std::uint64_t routeChangesFailed() const { return route_changes_failed_; }
  /// How often the advice guard acted (all zero when it is off).
  const GuardCounters& guardCounters() const { return guard_.counters(); }
  /// The guard's floor for this CAV [m/s] (0 when the guard is off).
  double guardFloorMps(const VehicleRecord& v) const { return guard_.floorMps(guardCav(v)); }
  /// Whether zone k is busy now (always false with busy zones off).
  bool zoneBusy(int cluster) const { return guard_.zoneBusy(cluster); }
  /// Zone k's smoothed mean of speed / own top speed of its mainline vehicles.
  double zoneSpeedShare(int cluster) const { return guard_.zoneSpeedShare(cluster); }
  /// Vehicles SUMO dropped at insertion so far: loaded from a flow, never departed, no
  /// longer waiting (they waited longer than --max-depart-delay). Asks SUMO.
  std::uint64_t insertionDropped() const;
  /// Vehicles in SUMO's insertion queue after the latest step: due, not yet on the road.
  std::uint64_t insertionWaiting() const { return insertion_waiting_; }
  /// Vehicle-seconds spent in the insertion queue so far (the integral of its length over
  /// time: every wait to enter, of vehicles that entered, were dropped or still wait).
  double insertionWaitVehicleSeconds() const { return insertion_wait_veh_s_; }

  /// "sumo x.y.z" of the running SUMO.
  std::string sumoVersion() const;
  /// Which C++ API this session was compiled against ("libsumo" or "libtraci").
  static const char* apiName();

 private:
  void readNetwork();
  /// readNetwork for a road of own_road_net_file: the layout from discoverOwnRoad, the edges
  /// the session needs from the layout's mainline order.
  void readOwnRoad();
  /// rsu_poses_ from the road's zones and the lane shapes SUMO has.
  void placeRsus();
  void onDeparted(const std::string& id);
  void readVehicles();
  void updateDerived(VehicleRecord& v) const;
  void manageExit(VehicleRecord& v);
  void continueLaneChange(VehicleRecord& v);
  /// lane_change_max_{accel,decel}_mps2: bound them for the advised change, then restore.
  void boundLaneChangeAcceleration(VehicleRecord& v);
  void restoreLaneChangeAcceleration(VehicleRecord& v);
  /// Bounds an advised change's acceleration while the CAV is above the guard's floor,
  /// lifts the bound below it.
  void updateLaneChangeBound(VehicleRecord& v);
  bool wholeOnEdge(const VehicleRecord& v) const;
  void requestLaneChange(VehicleRecord& v, double duration_s);
  void applyHeldCommand(VehicleRecord& v);
  void updateMergeMode(VehicleRecord& v);
  /// The guard's hand-back: hands a CAV in a busy zone back to its own route-aware driving,
  /// and takes it back once its zone is free.
  void updateHandback(VehicleRecord& v);
  /// A busy zone's gap acceptance for a CAV making its own changes, or its own value back
  /// (busy false).
  void setBusyGapAcceptance(VehicleRecord& v, bool busy) const;
  /// The busy zones' change bound on a handed-back CAV's acceleration around a lane change
  /// of its own (switched: it is in another lane or road part than a step ago).
  void updateBusyChangeBound(VehicleRecord& v, bool switched);
  void releaseBusyChangeBound(VehicleRecord& v);
  /// The CAV as the guard sees it now (its allowed speed asked of SUMO only if needed).
  GuardCav guardCav(const VehicleRecord& v) const;
  /// Sets a CAV's route to the rest of its own (to its off-ramp); false when it is not on it.
  bool routeToOwnExit(VehicleRecord& v);
  void removeVehicle(const std::string& id, std::vector<VehicleRecord>* removed);

  SessionOptions options_;
  std::unique_ptr<RoadLayout> road_;
  std::string end_edge_;         ///< last mainline edge: where onward routes go
  std::string insertion_edge_;   ///< first mainline edge: where mainline vehicles are inserted
  std::unordered_map<int, std::string> pre_exit_edge_;  ///< cluster -> mainline edge feeding its off-ramp
  std::unordered_set<std::string> index_shift_ahead_;   ///< edges whose successor numbers lanes differently
  std::vector<std::vector<std::pair<double, double>>> lane_shapes_;
  std::vector<MapPose> rsu_poses_;
  double lane_width_m_ = 3.2;
  double step_length_s_ = 0.1;
  double time_s_ = 0.0;
  std::uint64_t step_count_ = 0;
  std::vector<VehicleRecord> vehicles_;
  std::unordered_map<std::string, std::size_t> index_;
  StepEvents events_;
  bool open_ = false;
  std::uint64_t lane_changes_done_ = 0, lane_changes_dropped_ = 0, vanished_vehicles_ = 0;
  std::uint64_t route_changes_failed_ = 0;
  AdviceGuard guard_;
  /// The guard's zones, from this step's mainline vehicles.
  void updateZones();
  /// RSU zone (cluster) a vehicle's x falls in (RoadLayout::zoneAt), -1 = none.
  int zoneOf(const VehicleRecord& v) const { return road_->zoneAt(v.x_m); }
  /// No command of ours: its own car following (or, with own_car_following off, its speed).
  void holdOwnDriving(VehicleRecord& v) const;
  std::uint64_t loaded_vehicles_ = 0, departed_vehicles_ = 0;  ///< since the start
  std::uint64_t insertion_waiting_ = 0;  ///< insertion queue after the latest step
  double insertion_wait_veh_s_ = 0.0;    ///< its integral over time since the start
};

/// Route kind and clusters from a route id "r_<from>_<to>" (from: main | on<k>;
/// to: end | off<k>). @throws std::invalid_argument for another form.
void parseRouteId(const std::string& route_id, RouteKind* kind, int* entry_cluster,
                  int* exit_cluster);

}  // namespace palcas::sim
