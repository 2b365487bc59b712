#pragma once
// Loaders from ROS parameters to palcas_core's parameter structs, shared by the RSU node
// and the federation server (which builds the initial model from the same learning
// config). Each reads the keys of one config file, loaded by the launch files under a
// sub-namespace: ~reward/* (config/reward.yaml), ~learning/* (config/learning.yaml),
// ~state_scales/* (config/rsu.yaml). Every key is optional: absent = the paper's default
// compiled into the struct; present = checked. Header-only.

#include <palcas_core/learning/pdqn_config.h>
#include <palcas_core/reward/reward.h>
#include <palcas_core/state/state_builder.h>
#include <palcas_common/param_reader.h>

#include <limits>
#include <string>

namespace palcas::params {

/// ~<ns>/<name> for every name of rewardParamNames(); validated as a whole.
inline RewardParams loadRewardParams(palcas::common::ParamReader& p, const std::string& ns = "reward") {
  RewardParams r;
  for (const std::string& name : rewardParamNames()) {
    const std::string key = ns + "/" + name;
    setRewardParam(r, name, p.number(key, getRewardParam(r, name), -1e12, 1e12));
  }
  try {
    validateRewardParams(r);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument("parameters ~" + ns + "/*: " + e.what());
  }
  return r;
}

/// ~<ns>/* = config/learning.yaml's keys, one per PdqnConfig field.
inline PdqnConfig loadPdqnConfig(palcas::common::ParamReader& p, const std::string& ns = "learning") {
  constexpr int BIG = std::numeric_limits<int>::max();
  const std::string k = ns + "/";
  PdqnConfig c;
  // 0 (the shipped value) = 40 + the lane count of the bridge's road, filled in by the node
  // before it builds a network (palcas_common/bridge_road.h); a number pins it and is checked.
  c.state_size = p.integer(k + "state_size", 0, 0, BIG);
  c.hidden_sizes = p.get<std::vector<int>>(k + "hidden_sizes", c.hidden_sizes);
  c.batch_norm = p.get<bool>(k + "batch_norm", c.batch_norm);
  c.dropout = static_cast<float>(p.number(k + "dropout", c.dropout, 0.0, 1.0));
  c.huber_delta = static_cast<float>(p.number(k + "huber_delta", c.huber_delta, 0.0, 1e30));
  c.learning_rate = static_cast<float>(p.number(k + "learning_rate", c.learning_rate, 0.0, 1e30));
  c.weight_decay = static_cast<float>(p.number(k + "weight_decay", c.weight_decay, 0.0, 1e30));
  c.adam_beta1 = static_cast<float>(p.number(k + "adam_beta1", c.adam_beta1, 0.0, 1.0));
  c.adam_beta2 = static_cast<float>(p.number(k + "adam_beta2", c.adam_beta2, 0.0, 1.0));
  c.adam_eps = static_cast<float>(p.number(k + "adam_eps", c.adam_eps, 0.0, 1e30));
  c.batch_size = p.integer(k + "batch_size", c.batch_size, 1, BIG);
  c.gamma = static_cast<float>(p.number(k + "gamma", c.gamma, 0.0, 1.0));
  c.replay_capacity = p.integer(k + "replay_capacity", c.replay_capacity, 1, BIG);
  c.target_update_steps = p.integer(k + "target_update_steps", c.target_update_steps, 1, BIG);
  c.epsilon_start = p.number(k + "epsilon_start", c.epsilon_start, 0.0, 1.0);
  c.epsilon_final = p.number(k + "epsilon_final", c.epsilon_final, 0.0, 1.0);
  c.epsilon_decay = p.number(k + "epsilon_decay", c.epsilon_decay, 0.0, 1.0);
  c.accel_min_mps2 = static_cast<float>(p.number(k + "accel_min_mps2", c.accel_min_mps2, -100.0, 100.0));
  c.accel_max_mps2 = static_cast<float>(p.number(k + "accel_max_mps2", c.accel_max_mps2, -100.0, 100.0));
  c.accel_noise_std_mps2 =
      static_cast<float>(p.number(k + "accel_noise_std_mps2", c.accel_noise_std_mps2, 0.0, 100.0));
  c.multi_pass = p.get<bool>(k + "multi_pass", c.multi_pass);
  c.td_target_valid_actions = p.get<bool>(k + "td_target_valid_actions", c.td_target_valid_actions);
  c.target_soft_tau = static_cast<float>(p.number(k + "target_soft_tau", c.target_soft_tau, 0.0, 1.0));
  c.param_loss_accelerate_only =
      p.get<bool>(k + "param_loss_accelerate_only", c.param_loss_accelerate_only);
  c.epsilon_linear_rounds = p.number(k + "epsilon_linear_rounds", c.epsilon_linear_rounds, 0.0, 1e15);
  c.bf16_products = p.get<bool>(k + "bf16_products", c.bf16_products);
  c.seed = static_cast<std::uint64_t>(p.integer(k + "seed", static_cast<int>(c.seed), 0, BIG));
  try {
    PdqnConfig checked = c;  // a state size left to the road is checked once it is known
    if (checked.state_size == 0) checked.state_size = 41;  // 40 + L, L >= 1
    checked.validate();
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument("parameters ~" + ns + "/*: " + e.what());
  }
  return c;
}

/// ~<ns>/* = the state_scales map of config/rsu.yaml.
inline StateScales loadStateScales(palcas::common::ParamReader& p, const std::string& ns = "state_scales") {
  StateScales s;
  const std::string k = ns + "/";
  s.road_length_m = p.number(k + "road_length_m", s.road_length_m, 1e-3, 1e9);
  s.lateral_m = p.number(k + "lateral_m", s.lateral_m, 1e-3, 1e9);
  s.speed_mps = p.number(k + "speed_mps", s.speed_mps, 1e-3, 1e9);
  s.accel_mps2 = p.number(k + "accel_mps2", s.accel_mps2, 1e-3, 1e9);
  s.sensing_range_m = p.number(k + "sensing_range_m", s.sensing_range_m, 1e-3, 1e9);
  s.exit_range_m = p.number(k + "exit_range_m", s.exit_range_m, 1e-3, 1e9);
  s.jam_density_veh_per_km = p.number(k + "jam_density_veh_per_km", s.jam_density_veh_per_km, 1e-3, 1e9);
  validateScales(s);
  return s;
}

}  // namespace palcas::params
