#pragma once
// Every parameter of the federation server node in one struct, loaded in one place
// (loadFedServerOptions, the only caller of getParam). Meaning, defaults and ranges:
// README.md of this package and config/fedserver.yaml; ~learning/*: config/learning.yaml.

#include <palcas_common/param_reader.h>
#include <ros/node_handle.h>

#include <string>

#include <palcas_core/federation/federation_server.h>
#include <palcas_core/learning/pdqn_config.h>

namespace palcas::fedserver {

struct FedServerOptions {
  FederationOptions federation;  ///< expected_rsus, quorum, round_deadline_s, liveness_timeout_s, max_samples
  /// ~learning/*: builds the initial global model (PdqnAgent(learning).exportModel()).
  PdqnConfig learning;
  std::string checkpoint_dir;            ///< "" = no checkpoints
  /// The deployment's key file (palcas_core/common/message_auth.h): submissions without its
  /// tag are refused (counted as unauthenticated), served global models carry it. "" = off.
  std::string auth_key_file;
  bool resume = false;                   ///< start from checkpoint_dir instead of a fresh model
  double poll_period_s = 0.5;            ///< ROS-time period of the round-closing timer [s]
  /// Wall time to wait for the bridge's road when ~learning/state_size is 0 (from the road) [s].
  double road_wait_s = 60.0;
};

/// Reads the node's private parameters. @throws std::invalid_argument naming the key for
/// a missing required key, a wrong type, a value out of range, or an unknown key under
/// the node's namespace (a typo is an error, not a silent default).
FedServerOptions loadFedServerOptions(const ros::NodeHandle& private_nh,
                                  common::ParamDefaults* defaults = nullptr);

}  // namespace palcas::fedserver
