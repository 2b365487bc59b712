#include "palcas_sumo_bridge/run_files.h"

#include <nlohmann/json.hpp>
#include <palcas_core/common/atomic_file.h>
#include <palcas_core/common/build_info.h>
#include "palcas_sim/sumo_outputs.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace palcas::bridge {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

json number(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

/// Nearest-rank percentile of unsorted values; null when there are none.
json percentile(std::vector<float> values, double p) {
  if (values.empty()) return json(nullptr);
  const std::size_t rank = static_cast<std::size_t>(std::ceil(p / 100.0 * values.size()));
  const std::size_t index = rank == 0 ? 0 : rank - 1;
  std::nth_element(values.begin(), values.begin() + index, values.end());
  return json(values[index]);
}

/// FNV-1a 64: a short, stable fingerprint of the configuration snapshot.
std::string fingerprint(const std::string& text) {
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : text) {
    h ^= c;
    h *= 1099511628211ull;
  }
  char buf[17];
  std::snprintf(buf, sizeof(buf), "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

void writeAtomically(const std::string& path, const json& content) {
  writeFileAtomically(path, content.dump(2) + "\n");
}

/// A resumed training's episodes.csv written before columns were added at its end: the
/// header becomes the current one, the old rows stay (their new columns read as empty).
void upgradeHeader(const std::string& csv, const std::string& header) {
  std::ifstream in(csv);
  std::string first;
  std::getline(in, first);
  if (first == header || header.compare(0, first.size(), first) != 0 || first.empty()) return;
  std::stringstream rest;
  rest << in.rdbuf();
  in.close();
  writeFileAtomically(csv, header + "\n" + rest.str());
}

json twoPoint(const sim::TwoPointSpeed& s) {
  return {{"fast_mps", s.fast_mps}, {"slow_mps", s.slow_mps}, {"p_fast", s.p_fast}};
}

json insertion(const sim::InsertionSettings& i) {
  return {{"depart_lane", i.depart_lane}, {"depart_pos", i.depart_pos}, {"depart_speed", i.depart_speed}};
}

json scenarioJson(const sim::ScenarioConfig& c) {
  json shares = json::object();  // the shares in effect: an empty map is the default rule
  // (on an own road the default rule depends on its ramps: scenario/routes.rou.xml has the flows)
  const bool default_rule_of_clusters = c.route_shares.empty() && c.network_file.empty();
  for (const auto& [source, dest] : default_rule_of_clusters ? sim::defaultRouteShares(c.road.clusters) : c.route_shares)
    shares[source] = dest;
  const sim::RoadSpec& r = c.road;
  const json road = {{"clusters", r.clusters},
                     {"num_lanes", r.num_lanes},
                     {"cluster_length_m", r.cluster_length_m},
                     {"warmup_length_m", r.warmup_length_m},
                     {"merge_start_m", r.merge_start_m},
                     {"acceleration_lane_m", r.acceleration_lane_m},
                     {"exit_m", r.exit_m},
                     {"lane_width_m", r.lane_width_m},
                     {"speed_limit_mps", r.speed_limit_mps},
                     {"ramp_speed_limit_mps", r.ramp_speed_limit_mps},
                     {"zone_starts_m", r.zone_starts_m},
                     {"zone_start_edges", r.zone_start_edges}};
  return {{"scenario_dir", c.scenario_dir},
          {"road", road},
          {"generate_network", c.generate_network},
          {"network_file", c.network_file},
          {"mainline_edges", c.mainline_edges},
          {"route_file", c.route_file},
          {"penetration_rate", c.penetration_rate},
          {"seed", c.seed},
          {"duration_s", c.duration_s},
          {"mainline_flow_vphpl", c.mainline_flow_vphpl},
          {"onramp_flow_vphpl", c.onramp_flow_vphpl},
          {"route_shares", shares},
          {"cav_speed", twoPoint(c.cav_speed)},
          {"hdv_speed", twoPoint(c.hdv_speed)},
          {"mainline_insertion", insertion(c.mainline_insertion)},
          {"onramp_insertion", insertion(c.onramp_insertion)},
          {"max_depart_delay_s", c.max_depart_delay_s},
          {"time_to_teleport_s", c.time_to_teleport_s},
          {"step_length_s", c.step_length_s},
          {"lateral_resolution_m", c.lateral_resolution_m}};
}

json bridgeJson(const BridgeOptions& o) {
  json out = {{"advisory_control", o.session.advisory_control},
          {"cav_speed_mode", o.session.cav_speed_mode},
          {"cav_lane_change_mode", o.session.cav_lane_change_mode},
          {"lane_change_duration_s", o.session.lane_change_duration_s},
          {"own_car_following", o.session.own_car_following},
          {"own_merge", o.session.own_merge},
          {"max_advised_accel_mps2", o.session.max_advised_accel_mps2},
          {"lane_change_max_accel_mps2", o.session.lane_change_max_accel_mps2},
          {"lane_change_max_decel_mps2", o.session.lane_change_max_decel_mps2},
          {"assist_mode", o.session.assist_mode},
          {"assist_lane_change_mode", o.session.assist_lane_change_mode},
          {"cav_max_accel_mps2", o.session.cav_max_accel_mps2},
          {"cav_max_decel_mps2", o.session.cav_max_decel_mps2},
          {"remove_collided", o.session.remove_collided},
          {"sumo_outputs", o.sumo_outputs},
          {"sumo_fcd_period_s", o.sumo_fcd_period_s},
          {"expected_rsus", o.expected_rsus},
          {"inprocess_rsus", o.inprocess_rsus},
          {"lockstep_deadline_s", o.lockstep_deadline_s},
          {"lost_after_missed_steps", o.lost_after_missed_steps},
          {"max_advisory_age_steps", o.max_advisory_age_steps},
          {"real_time_factor", o.real_time_factor},
          {"exit_miss_margin_m", o.exit_miss_margin_m},
          {"merge_stop_speed_mps", o.merge_stop_speed_mps},
          {"merge_stop_window_m", o.merge_stop_window_m},
          {"comfort_threshold_mps2", o.comfort_threshold_mps2},
          {"gui", o.gui},
          {"sumo_warnings", o.sumo_warnings}};
  forEachGuardKey(o.session.guard, [&out](const char* key, const auto& value, auto...) { out[key] = value; });
  return out;
}

// Runs of one command on one traffic agree to the last digit only where these agree.
json buildJson() {
  const BuildInfo b = buildInfo();
  return {{"core_arch", b.arch}, {"core_simd", b.simd}, {"cpu", b.cpu}};
}

}  // namespace

std::string prepareScenario(const BridgeOptions& o) {
  const sim::ScenarioConfig& config = o.scenario;
  fs::create_directories(o.out_dir);
  const sim::ScenarioFiles files = sim::writeScenario(config, o.out_dir + "/scenario");
  json snapshot = {{"scenario", scenarioJson(config)}, {"bridge", bridgeJson(o)}};
  json manifest = {{"config", snapshot},
                   {"config_hash", fingerprint(snapshot.dump())},
                   {"seeds", {{"sumo", config.seed}}},
                   {"pr_percent", 100.0 * config.penetration_rate},
                   {"demand", {{"mainline_flow_vphpl", config.mainline_flow_vphpl},
                               {"onramp_flow_vphpl", config.onramp_flow_vphpl}}},
                   {"duration_s", config.duration_s},
                   {"git_commit", o.git_commit},
                   {"build", buildJson()},
                   {"command_line", o.command_line},
                   {"sumocfg", files.sumocfg_file}};
  writeAtomically(o.out_dir + "/manifest.json", manifest);
  return files.sumocfg_file;
}

void completeManifest(const BridgeOptions& o, const std::string& sumo_version,
                      const std::string& api_name, const MeasureRules& rules) {
  const std::string path = o.out_dir + "/manifest.json";
  std::ifstream in(path);
  json manifest = json::parse(in);
  manifest["sumo_version"] = sumo_version;
  manifest["sumo_api"] = api_name;
  manifest["measure_rules"] = {{"exit_x_m", rules.tracker.exit_x_m},
                               {"miss_margin_m", rules.tracker.miss_margin_m},
                               {"stop_speed_mps", rules.tracker.stop_speed_mps},
                               {"stop_window_m", rules.tracker.stop_window_m},
                               {"comfort_accel_mps2", rules.metrics.comfort_accel_mps2},
                               {"steady_state_from_s", rules.metrics.steady_state_from_s},
                               {"off_ramp_edges", rules.off_ramp_edges}};
  writeAtomically(path, manifest);
}

MeasureRules readMeasureRules(const std::string& manifest_path) {
  std::ifstream in(manifest_path);
  if (!in) throw std::runtime_error("cannot read '" + manifest_path + "'");
  json manifest;
  try {
    manifest = json::parse(in);
  } catch (const json::exception& e) {
    throw std::runtime_error("'" + manifest_path + "' is not JSON: " + e.what());
  }
  if (!manifest.contains("measure_rules"))
    throw std::runtime_error("'" + manifest_path + "' is not a PALCAS run manifest (no measure_rules)");
  const json& r = manifest["measure_rules"];
  MeasureRules rules;
  try {
    rules.tracker.exit_x_m = r.at("exit_x_m").get<std::vector<double>>();
    rules.tracker.miss_margin_m = r.at("miss_margin_m").get<double>();
    rules.tracker.stop_speed_mps = r.at("stop_speed_mps").get<double>();
    rules.tracker.stop_window_m = r.at("stop_window_m").get<double>();
    rules.metrics.comfort_accel_mps2 = r.at("comfort_accel_mps2").get<double>();
    // Manifests from before the steady-state window: its default.
    rules.metrics.steady_state_from_s = r.value("steady_state_from_s", rules.metrics.steady_state_from_s);
    if (r.contains("off_ramp_edges")) {
      rules.off_ramp_edges = r.at("off_ramp_edges").get<std::map<std::string, int>>();
    } else {
      // Manifests from before the off-ramps were listed: the edges were judged by the
      // generated roads' names, off_<k> for cluster k.
      for (std::size_t k = 0; k < rules.tracker.exit_x_m.size(); ++k)
        rules.off_ramp_edges["off_" + std::to_string(k)] = static_cast<int>(k);
    }
  } catch (const json::exception& e) {
    throw std::runtime_error("'" + manifest_path + "': measure_rules incomplete: " + e.what());
  }
  return rules;
}

std::string episodeDir(const BridgeOptions& o, int episode) {
  const bool several = o.episodes > 1 || o.first_episode > 0;
  return several ? o.out_dir + "/episode_" + std::to_string(episode) : o.out_dir;
}

sim::RunnerOptions runnerOptions(const BridgeOptions& o) {
  sim::RunnerOptions r;
  r.duration_s = o.scenario.duration_s;
  r.expected_rsus = o.expected_rsus;
  r.lost_after_missed_steps = o.lost_after_missed_steps;
  r.lockstep_deadline_s = o.lockstep_deadline_s;
  r.max_advisory_age_steps = static_cast<std::uint64_t>(o.max_advisory_age_steps);
  r.advisory_hold_steps = static_cast<std::uint64_t>(o.advisory_hold_steps);
  r.real_time_factor = o.real_time_factor;
  r.metrics_period_s = o.metrics_period_s;
  r.v2x = o.v2x;
  r.step_length_s = o.scenario.step_length_s;
  r.trajectory_period_steps = o.trajectory_period_steps;
  r.episode_dir = [o](int episode) { return episodeDir(o, episode); };
  return r;
}

sim::SessionOptions sessionOptionsFor(const BridgeOptions& o, const std::string& sumocfg,
                                      int episode) {
  sim::SessionOptions s = o.session;
  if (!o.scenario.network_file.empty()) {  // an own road: found again in the network SUMO runs
    s.own_road_net_file = (fs::path(sumocfg).parent_path() / "network.net.xml").string();
    s.own_road = sim::ownRoadOptions(o.scenario);
  }
  // Teleports end a vehicle's trip (counted apart from collisions), so its outcome is decided.
  s.sumo_args = {"-c", sumocfg, "--time-to-teleport.remove", "true", "--no-step-log", "true",
                 "--duration-log.disable", "true",
                 "--seed", std::to_string(o.scenario.seed + static_cast<unsigned>(episode))};
  // SUMO prints a warning for every emergency braking; off by default so progress stays
  // readable, on demand into the run folder (and the console).
  if (o.sumo_warnings) s.sumo_args.insert(s.sumo_args.end(), {"--log", o.out_dir + "/sumo.log"});
  else s.sumo_args.insert(s.sumo_args.end(), {"--no-warnings", "true"});
  s.sumo_binary = o.gui ? "sumo-gui" : "sumo";
  if (o.gui) {
    // Only the run's last episode may leave its window open: the others make way for the next.
    const bool last = episode + 1 >= o.first_episode + o.episodes;
    const bool stays_open = !o.gui_quit_on_end && last;
    s.sumo_args.insert(s.sumo_args.end(), {"--start", "true", "--quit-on-end", stays_open ? "false" : "true"});
    s.detach_sumo = stays_open;  // the bridge must not wait for a window its user closes
  }
  if (!o.sumo_outputs.empty()) {
    const std::string dir = episodeDir(o, episode);
    fs::create_directories(dir);
    const auto outputs = sim::sumoOutputArgs(o.sumo_outputs, dir, o.sumo_fcd_period_s);
    s.sumo_args.insert(s.sumo_args.end(), outputs.begin(), outputs.end());
  }
  return s;
}

// How often the advice guard acted: CAV seconds and the share of the time it covers.
json guardJson(const BridgeOptions& o, const sim::GuardCounters& g) {
  const double dt = o.scenario.step_length_s;
  auto share = [](std::uint64_t part, std::uint64_t whole) { return whole ? number(100.0 * part / whole) : json(nullptr); };
  return {{"enabled", o.session.guard.enabled},
          {"floor_speed_share", o.session.guard.floor_speed_share},
          {"accelerate_cav_s", dt * g.accelerate_steps},
          {"accelerate_floored_cav_s", dt * g.accelerate_floored_steps},
          {"accelerate_released_cav_s", dt * g.accelerate_released_steps},
          {"accelerate_advice", o.session.guard.accelerate_advice},
          {"accelerate_own_driving_cav_s", dt * g.accelerate_own_driving_steps},
          {"accelerate_guarded_pct", share(g.accelerate_floored_steps + g.accelerate_released_steps, g.accelerate_steps)},
          {"lane_change_cav_s", dt * g.lane_change_steps},
          {"lane_change_released_cav_s", dt * g.lane_change_released_steps},
          {"lane_change_guarded_pct", share(g.lane_change_released_steps, g.lane_change_steps)},
          {"lane_change_cooldown_s", o.session.guard.lane_change_cooldown_s},
          {"lane_changes_advised", g.lane_changes_advised},
          {"lane_changes_cooled_down", g.lane_changes_cooled_down},
          {"busy_speed_share", o.session.guard.busy_speed_share},
          {"busy_at_start", o.session.guard.busy_at_start},
          {"lane_changes_busy_refused", g.lane_changes_busy_refused},
          {"busy_zone_pct", share(g.busy_zone_steps, g.zone_steps)},
          {"busy_zone_s", o.scenario.step_length_s * g.busy_zone_steps},
          {"handback", o.session.guard.busy_handback},
          {"handbacks", g.handbacks},
          {"handback_cav_s", dt * g.handback_steps},
          {"handback_advice_dropped", g.handback_advice_dropped},
          {"busy_lc_assertive", o.session.guard.busy_lc_assertive},
          {"busy_change_max_accel_mps2", o.session.guard.busy_change_max_accel_mps2},
          {"busy_change_bounds", g.busy_change_bounds},
          {"busy_change_bound_cav_s", dt * g.busy_change_bound_steps},
          {"collided_cavs", g.collided_cavs},
          {"collided_handed_back", g.collided_handed_back},
          {"collided_busy_change_bounded", g.collided_busy_change_bounded},
          {"collided_advised_change", g.collided_advised_change},
          {"collided_accelerate", g.collided_accelerate},
          {"insertion_edge", o.session.guard.insertion_edge},
          {"lane_changes_insertion_refused", g.lane_changes_insertion_refused}};
}

// The advisories' way through the V2X channel (all zero but sent/delivered when it is off).
json v2xJson(const BridgeOptions& o, const v2x::DownlinkCounts& d) {
  auto link = [](const v2x::LinkModel& l) {
    return json{{"latency_s", l.latency_s}, {"jitter_s", l.jitter_s}, {"loss_probability", l.loss_probability}};
  };
  const v2x::ChannelParams& c = o.v2x;
  return {{"enabled", c.enabled},
          {"vehicle_state", link(c.vehicle_state)},
          {"advisory", link(c.advisory)},
          {"cluster_state", link(c.cluster_state)},
          {"rsu_range_m", std::isfinite(c.rsu_range_m) ? json(c.rsu_range_m) : json("inf")},
          {"max_advice_age_s", c.max_advice_age_s},
          {"keep_advice_s", c.keep_advice_s},
          {"keep_slowing_advice", c.keep_slowing_advice},
          {"advisories_sent", d.sent},
          {"advisories_delivered", d.delivered},
          {"advisories_applied_late", d.late},
          {"advisories_lost", d.lost},
          {"advisories_out_of_range", d.out_of_range},
          {"advisories_too_old", d.too_old},
          {"advice_mean_age_s", number(d.meanAgeS())}};
}

json exitsJson(const std::vector<metrics::ExitTally>& exits) {
  // The pooled DSR hides a zone that lets its exits pass while the others serve theirs.
  json out = json::array();
  for (std::size_t k = 0; k < exits.size(); ++k) {
    const metrics::ExitTally& e = exits[k];
    out.push_back({{"cluster", k},
                   {"exit_bound_cavs", e.exitBound()},
                   {"served", e.served},
                   {"missed", e.missed},
                   {"lost", e.lost},
                   {"censored", e.censored},
                   {"served_pct", number(e.servedPct())}});
  }
  return out;
}

void writeMetricsJson(const BridgeOptions& o, const RunSummary& s, int episode) {
  const metrics::EpisodeMetrics& m = s.metrics;
  json timing = json::array();
  for (const auto& [first, b] : s.timing.buckets())
    timing.push_back({{"vehicles_from", first},
                      {"vehicles_to", first + StepTimer::BUCKET_WIDTH - 1},
                      {"steps", b.steps},
                      {"sumo_ms_per_step", 1e3 * b.sumo_s / b.steps},
                      {"bridge_ms_per_step", 1e3 * b.bridge_s / b.steps},
                      {"lockstep_ms_per_step", 1e3 * b.lockstep_s / b.steps}});
  json out = {{"efficiency_all_mps", number(m.efficiency_all_mps)},
              {"efficiency_cav_mps", number(m.efficiency_cav_mps)},
              {"collision_rate_pct", number(m.collision_rate_pct)},
              {"dsr_pct", number(m.dsr_pct)},
              {"msr_pct", number(m.msr_pct)},
              {"comfort_share_pct", number(m.comfort_share_pct)},
              {"throughput_vph", number(m.throughput_vph)},
              {"insertion_dropped", s.insertion_dropped},
              {"insertion_waiting_end", s.insertion_waiting_end},
              {"unserved_vehicles", s.insertion_dropped + s.insertion_waiting_end},
              {"insertion_wait_veh_h", s.insertion_wait_veh_s / 3600.0},
              // Total time spent: on the road plus waiting to enter (the demand's own cost).
              {"total_time_spent_veh_h", (m.vehicle_seconds_on_road + s.insertion_wait_veh_s) / 3600.0},
              {"efficiency_steady_mps", number(m.efficiency_steady_mps)},
              {"exiting_cavs_censored", m.exiting_cavs_censored},
              {"dsr_censored_pct", number(m.dsr_censored_pct)},
              {"exits_by_cluster", exitsJson(s.exits)},
              {"merging_cavs_censored", m.merging_cavs_censored},
              {"msr_censored_pct", number(m.msr_censored_pct)},
              {"mean_travel_time_s", number(m.mean_travel_time_s)},
              {"lane_changes_per_cav", number(m.lane_changes_per_cav)},
              {"arrived", m.arrived},
              {"cav_lane_changes", m.cav_lane_changes},
              {"collisions", m.collisions},
              {"cav_collisions", m.cav_collisions},
              {"teleports", m.teleports},
              {"cavs_seen", m.cavs_seen},
              {"exiting_cavs", m.exiting_cavs},
              {"exits_ok", m.exits_ok},
              {"exits_missed", m.exits_missed},
              {"merging_cavs", m.merging_cavs},
              {"merges_ok", m.merges_ok},
              {"advisories", m.advisories_applied},
              {"advisories_rejected", m.advisories_rejected},
              {"rejections_by_reason", s.rejections_by_reason},
              {"lane_changes_done", s.lane_changes_done},
              {"lane_changes_dropped", s.lane_changes_dropped},
              {"vanished_vehicles", s.vanished_vehicles},
              {"route_changes_failed", s.route_changes_failed},
              {"guard", guardJson(o, s.guard)},
              {"v2x", v2xJson(o, s.downlink)},
              {"late_rsu_steps", m.late_rsu_steps},
              {"decision_ms_p50", percentile(s.decision_ms, 50)},
              {"decision_ms_p90", percentile(s.decision_ms, 90)},
              {"decision_ms_p99", percentile(s.decision_ms, 99)},
              {"decisions", s.decision_ms.size()},
              {"late_steps_by_rsu", s.late_by_rsu},
              {"sim_seconds", m.sim_seconds},
              {"wall_seconds", s.wall_seconds},
              {"real_time_factor", number(s.wall_seconds > 0 ? m.sim_seconds / s.wall_seconds : NAN)},
              {"steps", s.steps},
              {"pr_percent", 100.0 * o.scenario.penetration_rate},
              {"mainline_flow_vphpl", o.scenario.mainline_flow_vphpl},
              {"onramp_flow_vphpl", o.scenario.onramp_flow_vphpl},
              {"seed", o.scenario.seed + static_cast<unsigned>(episode)},
              {"episode", episode},
              {"episodes", o.episodes},
              {"step_timing", timing}};
  writeAtomically(o.out_dir + "/metrics.json", out);
  if (const std::string dir = episodeDir(o, episode); dir != o.out_dir) {  // each episode keeps its own file
    fs::create_directories(dir);
    writeAtomically(dir + "/metrics.json", out);
  }
  // One row per finished episode (also for a single one), for learning curves and for
  // ./palcas train --resume, which counts the rows: an episode cut short (SIGINT, or the
  // supervisor killed) must be redone, not counted; its metrics.json above still says how
  // far it got.
  if (m.sim_seconds + 1e-6 < o.scenario.duration_s) return;
  const std::string csv = o.out_dir + "/episodes.csv";
  const std::string header =
      "episode,seed,sim_seconds,wall_seconds,efficiency_all_mps,efficiency_cav_mps,"
      "collision_rate_pct,dsr_pct,msr_pct,comfort_share_pct,cavs_seen,exiting_cavs,"
      "merging_cavs,advisories,advisories_rejected,late_rsu_steps,mainline_flow_vphpl,"
      "onramp_flow_vphpl,pr_percent,throughput_vph,insertion_dropped,mean_travel_time_s,"
      "lane_changes_per_cav";
  const bool fresh = !fs::exists(csv);
  if (!fresh) upgradeHeader(csv, header);
  std::ofstream rows(csv, std::ios::app);
  if (fresh) rows << header << '\n';
  rows << episode << ',' << o.scenario.seed + static_cast<unsigned>(episode) << ',' << m.sim_seconds
       << ',' << s.wall_seconds << ',' << m.efficiency_all_mps << ',' << m.efficiency_cav_mps << ','
       << m.collision_rate_pct << ',' << m.dsr_pct << ',' << m.msr_pct << ',' << m.comfort_share_pct
       << ',' << m.cavs_seen << ',' << m.exiting_cavs << ',' << m.merging_cavs << ','
       << m.advisories_applied << ',' << m.advisories_rejected << ',' << m.late_rsu_steps << ','
       << o.scenario.mainline_flow_vphpl << ',' << o.scenario.onramp_flow_vphpl << ','
       << 100.0 * o.scenario.penetration_rate << ',' << m.throughput_vph << ','
       << s.insertion_dropped << ',' << m.mean_travel_time_s << ',' << m.lane_changes_per_cav
       << '\n';
}

RoadView prepareRvizView(const BridgeOptions& options,
                         const std::vector<std::vector<std::pair<double, double>>>& lane_shapes) {
  if (options.rviz_template.empty()) return frameRoad(roadExtent(lane_shapes), WindowPx{});
  std::ifstream in(options.rviz_template);
  if (!in) throw std::runtime_error("~rviz_template '" + options.rviz_template + "': cannot read it");
  std::stringstream text;
  text << in.rdbuf();
  try {
    const RoadView view = frameRoad(roadExtent(lane_shapes), windowOf(text.str()));
    writeFileAtomically(options.out_dir + "/palcas.rviz", withView(text.str(), view));
    return view;
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error("~rviz_template '" + options.rviz_template + "': " + e.what());
  }
}

}  // namespace palcas::bridge
