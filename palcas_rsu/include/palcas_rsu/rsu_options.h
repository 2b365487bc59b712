#pragma once
// Every parameter of the RSU node, loaded in one place (loadRsuNodeOptions, the only caller
// of the parameter server). Keys: README.md of this package; config/rsu.yaml (~rsu/*,
// ~state_scales/*), config/reward.yaml (~reward/*), config/learning.yaml (~learning/*).

#include <palcas_core/rsu/rsu_controller.h>
#include <palcas_core/v2x/v2x_channel.h>
#include <palcas_common/param_reader.h>
#include <ros/node_handle.h>

#include <string>
#include <vector>

namespace palcas::rsu {

/// Which of a policy folder's models an evaluating RSU loads (rsu/policy_model).
enum class PolicyModel {
  /// The folder's order: a training folder's global model, else the RSU's own final model,
  /// else the default. A shipped policy (tools/ship_policy.py --rsu-models) has no server
  /// model, so each RSU runs its own final model (PALCAS's departure).
  kFolderOrder,
  /// The paper: every RSU runs the federation's global model (fedserver/global_model.palcas,
  /// else default/model.palcas when the policy's train.json says it is the global model).
  /// A policy trained without a federation has none and loads in the folder's order.
  kGlobal,
};

struct RsuNodeOptions {
  RsuControllerOptions controller;
  /// Zone boundaries (~zones_m); RSU k manages [zones[k], zones[k+1]). Empty = the bridge's.
  std::vector<double> zones_m;
  bool whole_road = false;           ///< centralized baseline: one zone over every cluster
  int decision_period_steps = 10;    ///< bridge steps between decisions (1 s at 0.1 s steps)
  /// true: a decision's gradient steps run on a worker thread while the simulation goes
  /// on, joined before the next decision (same result as inline: the next decision sees
  /// the same weights). false: inline, after publishing the advisories.
  bool learner_thread = true;
  std::string policy_dir;            ///< eval: folder of a trained policy ("" = initial weights)
  PolicyModel policy_model = PolicyModel::kGlobal;  ///< which of its models (rsu/policy_model; paper: global)
  std::string checkpoint_dir;        ///< "" = no checkpoints; else <dir>/<rsu_id>/
  /// The deployment's key file (palcas_core/common/message_auth.h): advisories and
  /// submissions are signed with it, a global model without its tag is refused. "" =
  /// authentication off.
  std::string auth_key_file;
  bool resume = false;               ///< continue from the checkpoint in checkpoint_dir
  int checkpoint_every_decisions = 600;  ///< 0 = only at shutdown; 600 = every 10 sim minutes
  bool federation = true;            ///< false: no federation server (baselines)
  double federation_wait_s = 30.0;   ///< wall time to wait for the server at start [s]
  /// Sim time between heartbeat fetches while training between rounds [s], so the server
  /// can tell a busy RSU from a dead one with a short liveness timeout. 0 = none.
  double federation_heartbeat_s = 10.0;
  bool i2i = true;                   ///< false: no cluster-state exchange (global part unknown)
  double i2i_stale_after_s = 5.0;    ///< sim time after which a peer's state is stale [s]
  double register_timeout_s = 60.0;  ///< wall time to wait for the bridge's register service [s]
  /// Wall time a decision waits for its step's events and the neighbours' cluster states of
  /// the previous round (DecisionInputs) before deciding without them [s]. Below the bridge's
  /// lockstep_deadline_s (0.2 s), so a wait that ends this way is not also a late step.
  double decision_inputs_wait_s = 0.1;
  /// ~v2x/* (config/v2x.yaml): this RSU's side of the V2X channel, the vehicle states it
  /// hears (uplink) and the peers' cluster states (I2I). Off by default.
  v2x::ChannelParams v2x;
};

/// @throws std::invalid_argument naming the key for a bad, unknown or missing parameter.
RsuNodeOptions loadRsuNodeOptions(const ros::NodeHandle& private_nh,
                                  common::ParamDefaults* defaults = nullptr);

/// Sets x_start_m / x_end_m from zones_m and cluster_index (or the whole range for a
/// whole_road RSU). @throws std::invalid_argument naming zones_name when the zones do not
/// increase or have no zone for this cluster index.
void applyZones(RsuNodeOptions& o, const std::string& zones_name);

/// True when the zones, the lane count or the state size are left to the bridge's road
/// (~zones_m empty, ~rsu/num_lanes 0 or ~learning/state_size 0: the shipped files).
bool takesFromBridgeRoad(const RsuNodeOptions& o);

/// Fills what is left to the bridge's road (zones, L, state size 40 + L), checks what was
/// set against it (checkAgainstRoad) and validates the whole. @throws std::invalid_argument
/// naming both values on a mismatch, or the bad field.
void adoptBridgeRoad(RsuNodeOptions& o, const std::vector<double>& road_zones_m, int road_lanes);

/// Checks this RSU's zone and lane count against the bridge's road (zone boundaries along
/// the mainline and lane count, as the bridge publishes them). A centralized RSU (whole_road)
/// must span the whole road. @throws std::invalid_argument naming both values on a mismatch
/// (an RSU whose zone is not on the road would get no CAVs and nothing would say why).
void checkAgainstRoad(const RsuNodeOptions& o, const std::vector<double>& road_zones_m, int road_lanes);

/// policy_dir's value for an evaluation of an untrained network, asked for on purpose.
inline constexpr const char* RANDOM_POLICY = "random";

/// An evaluation runs trained weights (or the rule, or `random` on purpose): refused, naming
/// policy_dir, before anything waits for the bridge. @throws std::runtime_error.
void requireEvalWeights(const RsuNodeOptions& o);

/// The model an evaluating RSU loads from a policy's checkpoints folder, the one place of this
/// order: the federation's global model (fedserver/global_model.palcas), else the RSU's own
/// (<rsu_id>/model.palcas), else the policy's default (default/model.palcas, shipped beside
/// per-RSU models for a zone the training did not have). With PolicyModel::kGlobal a shipped
/// default that is the global model (train.json beside checkpoints/: "default_model":
/// "global") comes before the RSU's own.
/// @throws std::runtime_error naming the three candidates when none exists.
std::string policyFileIn(const std::string& checkpoints_dir, const std::string& rsu_id,
                         PolicyModel which = PolicyModel::kFolderOrder);

/// Whether the policy whose checkpoints folder is `checkpoints_dir` ships its default model
/// as the federation's global model (its train.json, one folder up, says "default_model":
/// "global", as tools/ship_policy.py writes it). False without a readable train.json.
bool defaultIsGlobalModel(const std::string& checkpoints_dir);

}  // namespace palcas::rsu
