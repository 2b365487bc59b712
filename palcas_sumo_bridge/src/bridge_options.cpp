#include "palcas_sumo_bridge/bridge_options.h"

#include <cmath>
#include <map>
#include <set>
#include <stdexcept>

namespace palcas::bridge {
namespace {

/// Reads optional parameters and remembers which keys it was asked for, so that a key
/// nobody asked for (a typo in a YAML file) is reported instead of silently ignored.
class ParamReader {
 public:
  explicit ParamReader(const ros::NodeHandle& nh) : nh_(nh) {}

  template <typename T>
  T get(const std::string& key, const T& default_value) {
    known_.insert(key);
    T value = default_value;
    if (nh_.hasParam(key) && !nh_.getParam(key, value))
      throw std::invalid_argument("parameter '" + nh_.resolveName(key) + "' has the wrong type");
    return value;
  }

  double getDouble(const std::string& key, double default_value, double min, double max) {
    const double value = get<double>(key, default_value);
    if (!std::isfinite(value) || value < min || value > max)
      throw std::invalid_argument("parameter '" + nh_.resolveName(key) + "' = " +
                                  std::to_string(value) + " is outside [" + std::to_string(min) +
                                  ", " + std::to_string(max) + "]");
    return value;
  }

  int getInt(const std::string& key, int default_value, int min, int max) {
    const int value = get<int>(key, default_value);
    if (value < min || value > max)
      throw std::invalid_argument("parameter '" + nh_.resolveName(key) + "' = " +
                                  std::to_string(value) + " is outside [" + std::to_string(min) +
                                  ", " + std::to_string(max) + "]");
    return value;
  }

  /// A map of maps of numbers (route shares), e.g. {main: {end: 0.55, off0: 0.15}}.
  std::map<std::string, sim::RouteShares> getShares(const std::string& key) {
    std::map<std::string, sim::RouteShares> out;
    std::vector<std::string> names;
    nh_.getParamNames(names);
    const std::string prefix = nh_.getNamespace() + "/" + key + "/";
    for (const std::string& name : names) {
      if (name.compare(0, prefix.size(), prefix) != 0) continue;
      const std::string rest = name.substr(prefix.size());
      const std::size_t slash = rest.find('/');
      if (slash == std::string::npos)
        throw std::invalid_argument("parameter '" + name + "' must be a map of destination shares");
      known_.insert(key + "/" + rest);
      double share = 0.0;
      if (!nh_.getParam(name, share) || !std::isfinite(share))
        throw std::invalid_argument("parameter '" + name + "' must be a number");
      out[rest.substr(0, slash)][rest.substr(slash + 1)] = share;
    }
    return out;
  }

  void rejectUnknownKeys() const {
    std::vector<std::string> names;
    nh_.getParamNames(names);
    const std::string ns = nh_.getNamespace() + "/";
    for (const std::string& name : names) {
      if (name.compare(0, ns.size(), ns) != 0) continue;
      const std::string key = name.substr(ns.size());
      if (!known_.count(key))
        throw std::invalid_argument("unknown parameter '" + name +
                                    "' (see palcas_sumo_bridge/README.md for the valid keys)");
    }
  }

 private:
  const ros::NodeHandle& nh_;
  std::set<std::string> known_;
};

/// ~scenario/*: one key per field of sim::ScenarioConfig, nested maps for the grouped ones.
sim::ScenarioConfig loadScenario(ParamReader& p) {
  sim::ScenarioConfig c;
  p.get<std::string>("scenario/scenario_dir", "");  // the launch's ~scenario_dir wins
  c.cluster_length_m = p.getDouble("scenario/cluster_length_m", c.cluster_length_m, 1.0, 1e5);
  c.penetration_rate = p.getDouble("scenario/penetration_rate", c.penetration_rate, 0.0, 1.0);
  c.seed = static_cast<unsigned int>(p.getInt("scenario/seed", static_cast<int>(c.seed), 0, 2147483647));
  c.duration_s = p.getDouble("scenario/duration_s", c.duration_s, 0.1, 1e7);
  c.mainline_flow_vphpl = p.getDouble("scenario/mainline_flow_vphpl", c.mainline_flow_vphpl, 0.0, 1e5);
  c.onramp_flow_vphpl = p.getDouble("scenario/onramp_flow_vphpl", c.onramp_flow_vphpl, 0.0, 1e5);
  for (auto [name, speed] : {std::pair{"cav_speed", &c.cav_speed}, std::pair{"hdv_speed", &c.hdv_speed}}) {
    const std::string k = std::string("scenario/") + name + "/";
    speed->fast_mps = p.getDouble(k + "fast_mps", speed->fast_mps, 0.0, 100.0);
    speed->slow_mps = p.getDouble(k + "slow_mps", speed->slow_mps, 0.0, 100.0);
    speed->p_fast = p.getDouble(k + "p_fast", speed->p_fast, 0.0, 1.0);
  }
  for (auto [name, ins] : {std::pair{"mainline_insertion", &c.mainline_insertion},
                           std::pair{"onramp_insertion", &c.onramp_insertion}}) {
    const std::string k = std::string("scenario/") + name + "/";
    ins->depart_lane = p.get<std::string>(k + "depart_lane", ins->depart_lane);
    ins->depart_pos = p.get<std::string>(k + "depart_pos", ins->depart_pos);
    ins->depart_speed = p.get<std::string>(k + "depart_speed", ins->depart_speed);
  }
  c.max_depart_delay_s = p.getDouble("scenario/max_depart_delay_s", c.max_depart_delay_s, -1.0, 1e7);
  c.time_to_teleport_s = p.getDouble("scenario/time_to_teleport_s", c.time_to_teleport_s, -1.0, 1e7);
  c.step_length_s = p.getDouble("scenario/step_length_s", c.step_length_s, 0.001, 10.0);
  c.lateral_resolution_m = p.getDouble("scenario/lateral_resolution_m", c.lateral_resolution_m, 0.0, 10.0);
  c.netconvert_binary = p.get<std::string>("scenario/netconvert_binary", c.netconvert_binary);
  const auto shares = p.getShares("scenario/route_shares");
  if (!shares.empty()) c.route_shares = shares;
  return c;
}

}  // namespace

BridgeOptions loadBridgeOptions(const ros::NodeHandle& private_nh) {
  ParamReader p(private_nh);
  BridgeOptions o;
  o.scenario = loadScenario(p);
  o.scenario.scenario_dir = p.get<std::string>("scenario_dir", "");
  if (o.scenario.scenario_dir.empty())
    throw std::invalid_argument("parameter '~scenario_dir' is required");
  sim::validateScenarioConfig(o.scenario);
  o.out_dir = p.get<std::string>("out_dir", "");
  if (o.out_dir.empty()) throw std::invalid_argument("parameter '~out_dir' is required");
  o.episodes = p.getInt("episodes", o.episodes, 1, 1000000);
  o.command_line = p.get<std::string>("command_line", "");
  o.git_commit = p.get<std::string>("git_commit", "");
  o.gui = p.get<bool>("gui", o.gui);
  o.sumo_warnings = p.get<bool>("sumo_warnings", o.sumo_warnings);
  o.session.advisory_control = p.get<bool>("advisory_control", o.session.advisory_control);
  o.session.cav_speed_mode = p.getInt("cav_speed_mode", o.session.cav_speed_mode, 0, 127);
  o.session.cav_lane_change_mode =
      p.getInt("cav_lane_change_mode", o.session.cav_lane_change_mode, 0, 4095);
  o.session.lane_change_duration_s =
      p.getDouble("lane_change_duration", o.session.lane_change_duration_s, 0.1, 60.0);
  o.session.cluster_length_m = o.scenario.cluster_length_m;
  o.expected_rsus = p.get<std::vector<std::string>>("expected_rsus", {});
  o.lockstep_deadline_s = p.getDouble("lockstep_deadline", o.lockstep_deadline_s, 0.001, 60.0);
  o.startup_timeout_s = p.getDouble("startup_timeout", o.startup_timeout_s, 0.0, 3600.0);
  o.min_subscribers = p.getInt("min_subscribers", o.min_subscribers, 0, 1000);
  o.lost_after_missed_steps = p.getInt("lost_after_missed_steps", o.lost_after_missed_steps, 1, 1000000);
  o.max_advisory_age_steps = p.getInt("max_advisory_age_steps", o.max_advisory_age_steps, 0, 1000);
  o.advisory_hold_steps = p.getInt("advisory_hold_steps", o.advisory_hold_steps, 1, 1000000);
  o.real_time_factor = p.getDouble("real_time_factor", o.real_time_factor, 0.0, 1000.0);
  o.metrics_period_s = p.getDouble("metrics_period", o.metrics_period_s, 0.1, 1e6);
  o.linger_s = p.getDouble("linger", o.linger_s, 0.0, 60.0);
  o.markers_every_steps = p.getInt("markers_every_steps", o.markers_every_steps, 1, 1000000);
  o.publish_tf = p.get<bool>("publish_tf", o.publish_tf);
  o.exit_miss_margin_m = p.getDouble("exit_miss_margin", o.exit_miss_margin_m, 0.0, 1000.0);
  o.merge_stop_speed_mps = p.getDouble("merge_stop_speed", o.merge_stop_speed_mps, 0.0, 10.0);
  o.merge_stop_window_m = p.getDouble("merge_stop_window", o.merge_stop_window_m, 0.0, 1000.0);
  o.comfort_threshold_mps2 = p.getDouble("comfort_threshold", o.comfort_threshold_mps2, 0.0, 20.0);
  p.rejectUnknownKeys();
  return o;
}

}  // namespace palcas::bridge
