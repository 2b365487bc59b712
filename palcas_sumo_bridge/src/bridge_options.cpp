#include "palcas_sumo_bridge/bridge_options.h"

#include <palcas_common/param_reader.h>
#include <palcas_common/v2x_params.h>
#include "palcas_sim/sumo_outputs.h"

#include <cmath>
#include <map>
#include <set>
#include <stdexcept>

namespace palcas::bridge {
namespace {

/// A map of maps of numbers (route shares), e.g. {main: {end: 0.55, off0: 0.15}}.
std::map<std::string, sim::RouteShares> readShares(palcas::common::ParamReader& p, const ros::NodeHandle& nh,
                                                   const std::string& key) {
  std::map<std::string, sim::RouteShares> out;
  std::vector<std::string> names;
  nh.getParamNames(names);
  const std::string prefix = nh.getNamespace() + "/" + key + "/";
  for (const std::string& name : names) {
    if (name.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string rest = name.substr(prefix.size());
    const std::size_t slash = rest.find('/');
    if (slash == std::string::npos)
      throw std::invalid_argument("parameter '" + name + "' must be a map of destination shares");
    out[rest.substr(0, slash)][rest.substr(slash + 1)] =
        p.number(key + "/" + rest, 0.0, 0.0, 1.0);
  }
  return out;
}

/// ~scenario/*: one key per field of sim::ScenarioConfig, nested maps for the grouped ones.
sim::ScenarioConfig loadScenario(palcas::common::ParamReader& p, const ros::NodeHandle& nh) {
  sim::ScenarioConfig c;
  p.accept("scenario/scenario_dir");  // the launch's ~scenario_dir wins
  // The road (sim::RoadSpec): ranges here, the geometry's consistency in validateRoadSpec.
  sim::RoadSpec& r = c.road;
  r.clusters = p.integer("scenario/road/clusters", r.clusters, 1, 1000);
  r.num_lanes = p.integer("scenario/road/num_lanes", r.num_lanes, 1, 100);
  for (auto [name, value] : {std::pair{"cluster_length_m", &r.cluster_length_m},
                             std::pair{"warmup_length_m", &r.warmup_length_m},
                             std::pair{"merge_start_m", &r.merge_start_m},
                             std::pair{"acceleration_lane_m", &r.acceleration_lane_m},
                             std::pair{"exit_m", &r.exit_m}, std::pair{"lane_width_m", &r.lane_width_m},
                             std::pair{"speed_limit_mps", &r.speed_limit_mps},
                             std::pair{"ramp_speed_limit_mps", &r.ramp_speed_limit_mps}})
    *value = p.number(std::string("scenario/road/") + name, *value, 1e-3, 1e6);
  r.zone_starts_m = p.get<std::vector<double>>("scenario/road/zone_starts_m", r.zone_starts_m);
  r.zone_start_edges = p.get<std::vector<std::string>>("scenario/road/zone_start_edges", r.zone_start_edges);
  c.generate_network = p.get<bool>("scenario/generate_network", c.generate_network);
  c.network_file = p.get<std::string>("scenario/network_file", c.network_file);
  c.mainline_edges = p.get<std::vector<std::string>>("scenario/mainline_edges", c.mainline_edges);
  c.route_file = p.get<std::string>("scenario/route_file", c.route_file);
  c.penetration_rate = p.number("scenario/penetration_rate", c.penetration_rate, 0.0, 1.0);
  c.seed = static_cast<unsigned int>(p.integer("scenario/seed", static_cast<int>(c.seed), 0, 2147483647));
  c.duration_s = p.number("scenario/duration_s", c.duration_s, 0.1, 1e7);
  c.mainline_flow_vphpl = p.number("scenario/mainline_flow_vphpl", c.mainline_flow_vphpl, 0.0, 1e5);
  c.onramp_flow_vphpl = p.number("scenario/onramp_flow_vphpl", c.onramp_flow_vphpl, 0.0, 1e5);
  for (auto [name, speed] : {std::pair{"cav_speed", &c.cav_speed}, std::pair{"hdv_speed", &c.hdv_speed}}) {
    const std::string k = std::string("scenario/") + name + "/";
    speed->fast_mps = p.number(k + "fast_mps", speed->fast_mps, 0.0, 100.0);
    speed->slow_mps = p.number(k + "slow_mps", speed->slow_mps, 0.0, 100.0);
    speed->p_fast = p.number(k + "p_fast", speed->p_fast, 0.0, 1.0);
  }
  for (auto [name, ins] : {std::pair{"mainline_insertion", &c.mainline_insertion},
                           std::pair{"onramp_insertion", &c.onramp_insertion}}) {
    const std::string k = std::string("scenario/") + name + "/";
    ins->depart_lane = p.get<std::string>(k + "depart_lane", ins->depart_lane);
    ins->depart_pos = p.get<std::string>(k + "depart_pos", ins->depart_pos);
    ins->depart_speed = p.get<std::string>(k + "depart_speed", ins->depart_speed);
  }
  c.max_depart_delay_s = p.number("scenario/max_depart_delay_s", c.max_depart_delay_s, -1.0, 1e7);
  c.time_to_teleport_s = p.number("scenario/time_to_teleport_s", c.time_to_teleport_s, -1.0, 1e7);
  c.step_length_s = p.number("scenario/step_length_s", c.step_length_s, 0.001, 10.0);
  c.lateral_resolution_m = p.number("scenario/lateral_resolution_m", c.lateral_resolution_m, 0.0, 10.0);
  c.netconvert_binary = p.get<std::string>("scenario/netconvert_binary", c.netconvert_binary);
  const auto shares = readShares(p, nh, "scenario/route_shares");
  if (!shares.empty()) c.route_shares = shares;
  return c;
}

}  // namespace

sim::GuardOptions loadGuardOptions(common::ParamReader& p) {
  sim::GuardOptions g;
  forEachGuardKey(g, [&p](const char* key, auto& value, auto... range) {
    if constexpr (sizeof...(range) == 0) value = p.get<bool>(key, value);
    else value = p.number(key, value, range...);
  });
  return g;
}

BridgeOptions loadBridgeOptions(const ros::NodeHandle& private_nh, common::ParamDefaults* defaults) {
  palcas::common::ParamReader p(private_nh, defaults);
  BridgeOptions o;
  o.scenario = loadScenario(p, private_nh);
  o.scenario.scenario_dir = p.get<std::string>("scenario_dir", "");
  if (o.scenario.scenario_dir.empty())
    throw std::invalid_argument("parameter '~scenario_dir' is required");
  sim::validateScenarioConfig(o.scenario);
  o.out_dir = p.get<std::string>("out_dir", "");
  if (o.out_dir.empty()) throw std::invalid_argument("parameter '~out_dir' is required");
  o.episodes = p.integer("episodes", o.episodes, 1, 1000000);
  o.first_episode = p.integer("first_episode", o.first_episode, 0, 1000000);
  o.command_line = p.get<std::string>("command_line", "");
  o.git_commit = p.get<std::string>("git_commit", "");
  o.gui = p.get<bool>("gui", o.gui);
  o.gui_quit_on_end = p.get<bool>("gui_quit_on_end", o.gui_quit_on_end);
  o.sumo_warnings = p.get<bool>("sumo_warnings", o.sumo_warnings);
  o.sumo_outputs = p.get<std::vector<std::string>>("sumo_outputs", o.sumo_outputs);
  o.sumo_fcd_period_s = p.number("sumo_fcd_period_s", o.sumo_fcd_period_s, 0.0, 3600.0);
  sim::sumoOutputArgs(o.sumo_outputs, o.out_dir, o.sumo_fcd_period_s);  // refuses unknown names now, not mid-run
  o.session.advisory_control = p.get<bool>("advisory_control", o.session.advisory_control);
  o.session.cav_speed_mode = p.integer("cav_speed_mode", o.session.cav_speed_mode, 0, 127);
  o.session.cav_lane_change_mode =
      p.integer("cav_lane_change_mode", o.session.cav_lane_change_mode, 0, 4095);
  o.session.lane_change_duration_s =
      p.number("lane_change_duration_s", o.session.lane_change_duration_s, 0.1, 60.0);
  o.session.own_car_following = p.get<bool>("own_car_following", o.session.own_car_following);
  o.session.own_merge = p.get<bool>("own_merge", o.session.own_merge);
  o.session.max_advised_accel_mps2 =
      p.number("max_advised_accel_mps2", o.session.max_advised_accel_mps2, 0.0, 20.0);
  o.session.remove_collided = p.get<bool>("remove_collided", o.session.remove_collided);
  o.session.cav_max_accel_mps2 = p.number("cav_max_accel_mps2", o.session.cav_max_accel_mps2, 0.0, 20.0);
  o.session.cav_max_decel_mps2 = p.number("cav_max_decel_mps2", o.session.cav_max_decel_mps2, 0.0, 20.0);
  o.session.lane_change_max_accel_mps2 =
      p.number("lane_change_max_accel_mps2", o.session.lane_change_max_accel_mps2, 0.0, 20.0);
  o.session.lane_change_max_decel_mps2 =
      p.number("lane_change_max_decel_mps2", o.session.lane_change_max_decel_mps2, 0.0, 20.0);
  o.session.guard = loadGuardOptions(p);
  o.session.assist_mode = p.get<bool>("assist_mode", o.session.assist_mode);
  o.session.assist_lane_change_mode =
      p.integer("assist_lane_change_mode", o.session.assist_lane_change_mode, 0, 4095);
  o.session.cluster_length_m = o.scenario.road.cluster_length_m;
  o.expected_rsus = p.get<std::vector<std::string>>("expected_rsus", {});
  o.inprocess_rsus = p.get<bool>("inprocess_rsus", o.inprocess_rsus);
  o.lockstep_deadline_s = p.number("lockstep_deadline_s", o.lockstep_deadline_s, 0.001, 60.0);
  o.startup_timeout_s = p.number("startup_timeout_s", o.startup_timeout_s, 0.0, 3600.0);
  o.min_subscribers = p.integer("min_subscribers", o.min_subscribers, 0, 1000);
  o.min_marker_subscribers = p.integer("min_marker_subscribers", o.min_marker_subscribers, 0, 1000);
  o.lost_after_missed_steps = p.integer("lost_after_missed_steps", o.lost_after_missed_steps, 1, 1000000);
  o.max_advisory_age_steps = p.integer("max_advisory_age_steps", o.max_advisory_age_steps, 0, 1000);
  o.v2x = params::loadChannelParams(p);
  o.auth_key_file = p.get<std::string>("auth_key_file", o.auth_key_file);
  if (o.auth_key_file == "none") o.auth_key_file.clear();  // the launch files' "not set"
  o.trajectory_period_steps =
      p.integer("trajectory_period_steps", o.trajectory_period_steps, 0, 1000000);
  o.advisory_hold_steps = p.integer("advisory_hold_steps", o.advisory_hold_steps, 1, 1000000);
  o.real_time_factor = p.number("real_time_factor", o.real_time_factor, 0.0, 1000.0);
  o.metrics_period_s = p.number("metrics_period_s", o.metrics_period_s, 0.1, 1e6);
  o.linger_s = p.number("linger_s", o.linger_s, 0.0, 60.0);
  o.markers_every_steps = p.integer("markers_every_steps", o.markers_every_steps, 1, 1000000);
  o.publish_tf = p.get<bool>("publish_tf", o.publish_tf);
  o.rviz_template = p.get<std::string>("rviz_template", o.rviz_template);
  if (o.rviz_template == "none") o.rviz_template.clear();  // the launch files' "not set"
  o.exit_miss_margin_m = p.number("exit_miss_margin_m", o.exit_miss_margin_m, 0.0, 1000.0);
  o.merge_stop_speed_mps = p.number("merge_stop_speed_mps", o.merge_stop_speed_mps, 0.0, 10.0);
  o.merge_stop_window_m = p.number("merge_stop_window_m", o.merge_stop_window_m, 0.0, 1000.0);
  o.comfort_threshold_mps2 = p.number("comfort_threshold_mps2", o.comfort_threshold_mps2, 0.0, 20.0);
  o.steady_state_from_s = p.number("steady_state_from_s", o.steady_state_from_s, 0.0, 1e7);
  p.rejectUnknownKeys("palcas_sumo_bridge/README.md");
  return o;
}

}  // namespace palcas::bridge
