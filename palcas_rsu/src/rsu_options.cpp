#include "palcas_rsu/rsu_options.h"

#include <palcas_common/param_reader.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <regex>

#include "palcas_common/core_params.h"
#include "palcas_common/v2x_params.h"
#include "palcas_core/state/state_layout.h"

namespace palcas::rsu {

namespace {

// A string parameter that must be one of two words: true for `second`, false for `first`
// (the default); anything else is refused naming the key, the value and both words.
bool secondOf(palcas::common::ParamReader& p, const char* key, const std::string& first,
              const std::string& second) {
  const std::string value = p.get<std::string>(key, first);
  if (value != first && value != second)
    throw std::invalid_argument("parameter '" + p.fullName(key) + "' is '" + value + "', not one of " + first +
                                ", " + second);
  return value == second;
}

}  // namespace

RsuNodeOptions loadRsuNodeOptions(const ros::NodeHandle& private_nh, common::ParamDefaults* defaults) {
  palcas::common::ParamReader p(private_nh, defaults);
  RsuNodeOptions o;
  RsuControllerOptions& c = o.controller;
  c.rsu_id = p.get<std::string>("rsu/rsu_id", c.rsu_id);
  c.cluster_index = p.integer("rsu/cluster_index", c.cluster_index, 0, 1000);
  c.x_start_m = p.number("rsu/x_start_m", c.x_start_m, -1e9, 1e9);
  c.x_end_m = p.number("rsu/x_end_m", c.x_end_m, -1e9, 1e9);
  // Zones, lane count and state size come from the bridge's road unless set here (then they
  // are checked against it): adoptBridgeRoad.
  o.zones_m = p.get<std::vector<double>>("zones_m", {});
  o.whole_road = p.get<bool>("whole_road", false);
  if (!o.zones_m.empty()) applyZones(o, p.fullName("zones_m"));
  c.num_lanes = p.integer("rsu/num_lanes", 0, 0, 100);  // 0 = the bridge's road
  c.train = p.get<bool>("rsu/train", c.train);
  if (secondOf(p, "rsu/advice", "network", "rules")) c.advice_source = AdviceSource::kRules;
  RuleAdvisorOptions& r = c.rules;
  r.exit_distance_per_lane_m = p.number("rules/exit_distance_per_lane_m", r.exit_distance_per_lane_m, 1e-3, 1e6);
  r.exit_margin_m = p.number("rules/exit_margin_m", r.exit_margin_m, 0.0, 1e6);
  r.through_keep_out_lanes = p.integer("rules/through_keep_out_lanes", r.through_keep_out_lanes, 0, 100);
  r.advise_merge = p.get<bool>("rules/advise_merge", r.advise_merge);
  c.rule_residual = p.get<bool>("rsu/rule_residual", c.rule_residual);
  c.residual_margin = p.number("rsu/residual_margin", c.residual_margin, 0.0, 1e9);
  if (secondOf(p, "rsu/residual_default", "rule", "keep")) c.residual_default = ResidualDefault::kKeep;
  c.no_left_for_exit_within_m = p.number("rsu/no_left_for_exit_within_m", c.no_left_for_exit_within_m, 0.0, 1e9);
  c.lane_change_dwell_s = p.number("rsu/lane_change_dwell_s", c.lane_change_dwell_s, 0.0, 1e6);
  c.exit_rule_override = p.get<bool>("rsu/exit_rule_override", c.exit_rule_override);
  c.exit_rule_below_density_veh_per_km =
      p.number("rsu/exit_rule_below_density_veh_per_km", c.exit_rule_below_density_veh_per_km, 0.0, 1e6);
  c.exit_rule_density_window_s =
      p.number("rsu/exit_rule_density_window_s", c.exit_rule_density_window_s, 0.0, 1e6);
  c.exit_rule_below_inflow_veh_per_h_per_lane = p.number(
      "rsu/exit_rule_below_inflow_veh_per_h_per_lane", c.exit_rule_below_inflow_veh_per_h_per_lane, 0.0, 1e6);
  c.exit_rule_inflow_window_s = p.number("rsu/exit_rule_inflow_window_s", c.exit_rule_inflow_window_s, 1e-3, 1e6);
  c.lane_change_cost = p.number("rsu/lane_change_cost", c.lane_change_cost, 0.0, 1e6);
  c.gradient_steps_per_decision =
      p.number("rsu/gradient_steps_per_decision", c.gradient_steps_per_decision, 0.0, 1000.0);
  c.federation_interval_steps = p.count("rsu/federation_interval_steps", c.federation_interval_steps, 0);
  c.personal_head_layers = static_cast<size_t>(
      p.integer("rsu/personal_head_layers", static_cast<int>(c.personal_head_layers), 0, 100));
  TerminalRewards& t = c.terminal;
  t.collision_penalty = p.number("rsu/collision_penalty", t.collision_penalty, 0.0, 1e9);
  t.exit_taken_bonus = p.number("rsu/exit_taken_bonus", t.exit_taken_bonus, 0.0, 1e9);
  t.exit_missed_penalty = p.number("rsu/exit_missed_penalty", t.exit_missed_penalty, 0.0, 1e9);
  t.exit_missed_terminal = p.get<bool>("rsu/exit_missed_terminal", t.exit_missed_terminal);
  t.merge_failed_penalty = p.number("rsu/merge_failed_penalty", t.merge_failed_penalty, 0.0, 1e9);
  c.reward_over_period = p.get<bool>("rsu/reward_over_period", c.reward_over_period);
  o.learner_thread = p.get<bool>("rsu/learner_thread", o.learner_thread);
  o.decision_period_steps = p.integer("rsu/decision_period_steps", o.decision_period_steps, 1, 100000);
  c.reward = params::loadRewardParams(p);
  c.scales = params::loadStateScales(p);
  c.pdqn = params::loadPdqnConfig(p);
  o.policy_dir = p.get<std::string>("policy_dir", o.policy_dir);
  if (secondOf(p, "rsu/policy_model", "global", "folder_order")) o.policy_model = PolicyModel::kFolderOrder;
  o.checkpoint_dir = p.get<std::string>("checkpoint_dir", o.checkpoint_dir);
  o.auth_key_file = p.get<std::string>("auth_key_file", o.auth_key_file);
  if (o.auth_key_file == "none") o.auth_key_file.clear();  // the launch files' "not set"
  o.resume = p.get<bool>("resume", o.resume);
  if (o.resume && o.checkpoint_dir.empty())
    throw std::invalid_argument("parameter '" + p.fullName("resume") + "' is true but '" +
                                p.fullName("checkpoint_dir") + "' is empty: nothing to resume from");
  o.checkpoint_every_decisions =
      p.integer("checkpoint_every_decisions", o.checkpoint_every_decisions, 0, std::numeric_limits<int>::max());
  o.federation = p.get<bool>("federation", o.federation);
  if (!o.federation) c.federation_interval_steps = 0;  // never due
  o.federation_wait_s = p.number("federation_wait_s", o.federation_wait_s, 0.0, 3600.0);
  o.federation_heartbeat_s = p.number("federation_heartbeat_s", o.federation_heartbeat_s, 0.0, 1e6);
  o.i2i = p.get<bool>("i2i", o.i2i);
  o.i2i_stale_after_s = p.number("i2i_stale_after_s", o.i2i_stale_after_s, 1e-3, 1e9);
  o.register_timeout_s = p.number("register_timeout_s", o.register_timeout_s, 0.0, 3600.0);
  o.decision_inputs_wait_s = p.number("decision_inputs_wait_s", o.decision_inputs_wait_s, 0.0, 60.0);
  o.v2x = params::loadChannelParams(p);
  p.rejectUnknownKeys("palcas_rsu/README.md");
  if (!takesFromBridgeRoad(o)) c.validate();  // else adoptBridgeRoad validates
  return o;
}

void applyZones(RsuNodeOptions& o, const std::string& zones_name) {
  RsuControllerOptions& c = o.controller;
  for (std::size_t i = 1; i < o.zones_m.size(); ++i)
    if (!(o.zones_m[i] > o.zones_m[i - 1]))
      throw std::invalid_argument("parameter '" + zones_name + "' must increase");
  const int zones = static_cast<int>(o.zones_m.size()) - 1;
  if (zones < 1) throw std::invalid_argument("parameter '" + zones_name + "' needs at least 2 boundaries");
  if (o.whole_road) {
    c.x_start_m = o.zones_m.front();
    c.x_end_m = o.zones_m.back();
  } else if (c.cluster_index >= zones) {
    throw std::invalid_argument("rsu/cluster_index = " + std::to_string(c.cluster_index) + " but '" +
                                zones_name + "' has " + std::to_string(zones) + " zone(s)");
  } else {
    c.x_start_m = o.zones_m[c.cluster_index];
    c.x_end_m = o.zones_m[c.cluster_index + 1];
  }
}

bool takesFromBridgeRoad(const RsuNodeOptions& o) {
  return o.zones_m.empty() || o.controller.num_lanes == 0 || o.controller.pdqn.state_size == 0;
}

void adoptBridgeRoad(RsuNodeOptions& o, const std::vector<double>& road_zones_m, int road_lanes) {
  RsuControllerOptions& c = o.controller;
  if (road_lanes < 1) throw std::invalid_argument("the bridge's road has " + std::to_string(road_lanes) + " lanes");
  if (o.zones_m.empty()) {
    o.zones_m = road_zones_m;
    applyZones(o, "the bridge's road zones");
  }
  if (c.num_lanes == 0) c.num_lanes = road_lanes;
  if (c.pdqn.state_size == 0) c.pdqn.state_size = StateLayout(c.num_lanes).size();
  checkAgainstRoad(o, road_zones_m, road_lanes);
  c.validate();
}

void checkAgainstRoad(const RsuNodeOptions& o, const std::vector<double>& road_zones_m, int road_lanes) {
  const RsuControllerOptions& c = o.controller;
  if (road_lanes != c.num_lanes)
    throw std::invalid_argument("the bridge's road has " + std::to_string(road_lanes) +
                                " lanes but rsu/num_lanes is " + std::to_string(c.num_lanes) +
                                " (the state size depends on it)");
  if (road_zones_m.size() < 2) return;  // nothing to compare with
  const int zones = static_cast<int>(road_zones_m.size()) - 1;
  double start = road_zones_m.front(), end = road_zones_m.back();
  std::string which = "the bridge's road spans";
  if (!o.whole_road) {
    if (c.cluster_index >= zones)
      throw std::invalid_argument("rsu/cluster_index is " + std::to_string(c.cluster_index) +
                                  " but the bridge's road has " + std::to_string(zones) + " zone(s)");
    start = road_zones_m[c.cluster_index];
    end = road_zones_m[c.cluster_index + 1];
    which = "zone " + std::to_string(c.cluster_index) + " of the bridge's road is";
  }
  constexpr double TOLERANCE_M = 0.5;  // netconvert places edge ends to the centimetre
  if (std::abs(start - c.x_start_m) > TOLERANCE_M || std::abs(end - c.x_end_m) > TOLERANCE_M) {
    char text[256];
    std::snprintf(text, sizeof text, "this RSU's zone is [%.1f, %.1f) m but %s [%.1f, %.1f) m",
                  c.x_start_m, c.x_end_m, which.c_str(), start, end);
    throw std::invalid_argument(text);
  }
}

void requireEvalWeights(const RsuNodeOptions& o) {
  if (o.controller.train || o.policy_dir == RANDOM_POLICY) return;
  if (o.controller.advice_source == AdviceSource::kRules) return;  // the rule needs no weights
  if (o.policy_dir.empty())
    throw std::runtime_error(
        "mode eval needs trained weights and policy_dir is not set: give policy_dir:=DIR (a training's "
        "checkpoints/ folder; system.launch's default 'shipped' is policies/<arm>/checkpoints; "
        "./palcas train makes new ones), or policy_dir:=random to evaluate an untrained network on "
        "purpose. Only mode train starts from random weights");
  if (!std::filesystem::is_directory(o.policy_dir))
    throw std::runtime_error("policy_dir '" + o.policy_dir + "' is not a folder (eval needs a training's "
                             "checkpoints/ folder, e.g. policies/palcas/checkpoints)");
}

bool defaultIsGlobalModel(const std::string& checkpoints_dir) {
  std::ifstream in(std::filesystem::path(checkpoints_dir) / ".." / "train.json");
  if (!in) return false;
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // tools/ship_policy.py writes the record with json.dump: "default_model": "global".
  static const std::regex KEY("\"default_model\"\\s*:\\s*\"global\"");
  return std::regex_search(text, KEY);
}

std::string policyFileIn(const std::string& checkpoints_dir, const std::string& rsu_id, PolicyModel which) {
  namespace fs = std::filesystem;
  const fs::path dir(checkpoints_dir);
  const fs::path candidates[] = {dir / "fedserver" / "global_model.palcas", dir / rsu_id / "model.palcas",
                                 dir / "default" / "model.palcas"};
  if (which == PolicyModel::kGlobal && !fs::exists(candidates[0]) && fs::exists(candidates[2]) &&
      defaultIsGlobalModel(checkpoints_dir))
    return candidates[2].string();
  for (const fs::path& f : candidates)
    if (fs::exists(f)) return f.string();
  throw std::runtime_error("policy folder '" + checkpoints_dir + "' holds no model for " + rsu_id + ": none of " +
                           candidates[0].string() + ", " + candidates[1].string() + ", " + candidates[2].string());
}

}  // namespace palcas::rsu
