#pragma once
// Every parameter of the bridge node in one struct, loaded in one place
// (loadBridgeOptions, the only caller of getParam). Defaults and meaning: README.md of
// this package and config/bridge.yaml.

#include <palcas_core/v2x/v2x_channel.h>
#include <palcas_common/param_reader.h>
#include <ros/node_handle.h>

#include <string>
#include <vector>

#include "palcas_sim/scenario.h"
#include "palcas_sim/sumo_session.h"

namespace palcas::bridge {

/// The advice guard's keys guard_* (config/bridge.yaml documents each) with their field of
/// sim::GuardOptions: f(key, flag) for a bool, f(key, number, min, max) for a number in
/// [min, max]. The loader and the run's bridge parameters both walk it, so a new guard
/// option is a field, a line here and its key in config/bridge.yaml.
template <class GuardOptionsT, class F>
void forEachGuardKey(GuardOptionsT& g, F&& f) {
  f("guard_enabled", g.enabled);
  f("guard_floor_speed_share", g.floor_speed_share, 0.0, 1.0);
  f("guard_lane_change_cooldown_s", g.lane_change_cooldown_s, 0.0, 3600.0);
  f("guard_busy_speed_share", g.busy_speed_share, 0.0, 1.0);
  f("guard_busy_leave_share", g.busy_leave_share, 0.0, 1.0);
  f("guard_busy_window_s", g.busy_window_s, 0.1, 3600.0);
  f("guard_busy_at_start", g.busy_at_start);
  f("guard_busy_floor_speed_share", g.busy_floor_speed_share, 0.0, 1.0);
  f("guard_busy_handback", g.busy_handback);
  f("guard_busy_assist_advice", g.busy_assist_advice);
  f("guard_busy_lc_assertive", g.busy_lc_assertive, 0.0, 100.0);
  f("guard_busy_change_max_accel_mps2", g.busy_change_max_accel_mps2, 0.0, 20.0);
  f("guard_busy_change_hold_s", g.busy_change_hold_s, 0.0, 600.0);
  f("guard_insertion_edge", g.insertion_edge);
  f("guard_accelerate_advice", g.accelerate_advice);
}

/// The advice guard's options from the keys guard_* (forEachGuardKey).
/// @throws std::invalid_argument naming a key of the wrong type or out of its range.
sim::GuardOptions loadGuardOptions(common::ParamReader& p);

struct BridgeOptions {
  // Scenario and run: ~scenario/* (config/scenarios/<name>/scenario.yaml) holds the road's
  // demand, PR, seed, duration and cluster length; ~scenario_dir overrides its folder.
  sim::ScenarioConfig scenario;
  std::string out_dir;             ///< run folder: generated scenario, metrics.json, manifest.json
  int episodes = 1;                ///< episodes in this run; episode k uses SUMO seed + k
  int first_episode = 0;           ///< number of the first episode (a resumed training continues)
  std::string command_line;        ///< how the run was started, for the manifest
  std::string git_commit;          ///< for the manifest
  // SUMO.
  bool gui = false;                ///< true: external sumo-gui over libtraci
  /// With gui: sumo-gui quits when the run ends (true) or stays open on the last episode's
  /// final state until its user closes it (false, the default: a window that vanishes as the
  /// run ends shows nothing). Earlier episodes' windows always quit.
  bool gui_quit_on_end = false;
  bool sumo_warnings = false;      ///< true: SUMO's warnings on the console and in <out_dir>/sumo.log
  /// SUMO's own output files by name (palcas_sim/sumo_outputs.h: fcd, tripinfo, ssm,
  /// lanechange, collision, summary, statistic), written into the run folder (episode_<k>/
  /// when several episodes). Empty = none.
  std::vector<std::string> sumo_outputs;
  double sumo_fcd_period_s = 1.0;  ///< FCD sampling period [s]; 0 = every step
  sim::SessionOptions session;
  // Lockstep with the RSUs.
  std::vector<std::string> expected_rsus;  ///< empty = no RSUs (SUMO-native)
  /// true: the expected RSUs run inside this process (inprocess_rsus.h), built from the
  /// parameters under /<rsu_id>/rsu/; no RSU node runs. false: RSU nodes over topics.
  bool inprocess_rsus = false;
  double lockstep_deadline_s = 0.2;        ///< wall time an RSU has to answer a step [s]
  double startup_timeout_s = 30.0;         ///< wall time to wait for every RSU to register [s]
  int min_subscribers = 0;  ///< wait (up to startup_timeout_s) for this many vehicle_states subscribers
  int min_marker_subscribers = 0;  ///< and for this many markers subscribers (the view's recorder)
  int lost_after_missed_steps = 50;        ///< consecutive misses before an RSU is lost
  int max_advisory_age_steps = 0;          ///< 0 = an advisory must answer the current step
  /// ~v2x/* (config/v2x.yaml): the V2X channel; the bridge applies the advisories' downlink
  /// (latency, loss, range, max age), the RSUs the rest. Off by default.
  v2x::ChannelParams v2x;
  /// Key file of the deployment (palcas_core/common/message_auth.h): advisory arrays without
  /// its tag are refused. "" = authentication off (any publisher may advise; warned at start).
  std::string auth_key_file;
  /// An applied advisory holds this many steps; then, without a new one, the CAV keeps its
  /// speed. CAVs of an RSU that misses a step's deadline keep their speed at once.
  int advisory_hold_steps = 10;
  // Pace and outputs.
  double real_time_factor = 0.0;   ///< 0 = as fast as possible; e.g. 1.0 = real time
  double metrics_period_s = 60.0;  ///< simulated time between EpisodeMetrics messages [s]
  double linger_s = 1.0;           ///< wall time to stay up after the episode, so subscribers drain [s]
  /// Record trajectories.csv (every vehicle every N steps) and decisions.csv into the run
  /// folder (episode_<k>/ when several episodes); 0 = record nothing.
  int trajectory_period_steps = 0;
  int markers_every_steps = 5;     ///< rviz markers every N steps (only with subscribers)
  /// rviz configuration to frame on this road: written with the road's view as
  /// <out_dir>/palcas.rviz; "" = write none (markers framed for a 1400x860 window).
  std::string rviz_template;
  bool publish_tf = true;          ///< map -> vehicle and map -> RSU zone frames (only with subscribers)
  // Metrics rules.
  double exit_miss_margin_m = 20.0;   ///< on the mainline this far past its exit = missed [m]
  double merge_stop_speed_mps = 0.1;  ///< "stopped" below this speed [m/s] ...
  double merge_stop_window_m = 10.0;  ///< ... within this distance of the acceleration lane's end [m]
  double comfort_threshold_mps2 = 1.47;
  /// efficiency_steady_mps counts samples from this simulation time on [s] (the road has filled).
  double steady_state_from_s = 600.0;
};

/// Reads the private parameters of the node, ~scenario/* included. @throws
/// std::invalid_argument naming the key for a value out of range, a wrong type, or an
/// unknown key under the node's namespace.
BridgeOptions loadBridgeOptions(const ros::NodeHandle& private_nh,
                                  common::ParamDefaults* defaults = nullptr);

}  // namespace palcas::bridge
