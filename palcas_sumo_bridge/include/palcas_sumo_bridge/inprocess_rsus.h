#pragma once
// The bridge's in-process mode (~inprocess_rsus): the road's RSUs run inside the bridge
// process, each an RsuDecider (palcas_rsu/rsu_decider.h, the RSU node's own decision path)
// built from the parameters rsu.launch puts under /<rsu_id>/rsu/. Each step goes to them
// as a function call instead of a topic, so the per-step path has no ROS messages on the
// wire, no lockstep wait and no serialisation; the learners still run on their own threads
// (RsuSchedule) while SUMO steps. What stays on ROS: the federation server (its services,
// once per round), and the RSUs' status, cluster-state and model topics (published, cheap
// without subscribers, so bags and rviz still see them).

#include <palcas_core/common/message_auth.h>
#include <palcas_msgs/AdvisoryArray.h>
#include <palcas_msgs/VehicleEventArray.h>
#include <palcas_msgs/VehicleStateArray.h>
#include <palcas_rsu/rsu_decider.h>
#include <ros/ros.h>

#include <memory>
#include <string>
#include <vector>

namespace palcas::bridge {

class InProcessRsus {
 public:
  /// One RsuDecider per id, from /<id>/rsu/ parameters, on this road (zone boundaries along
  /// the mainline and lane count: what the bridge publishes for RSU nodes), with a federation
  /// client over /fedserver's services when an RSU trains with federation.
  /// @throws std::exception naming the RSU and what failed (a missing or bad parameter, no
  ///         policy, a zone not on the road).
  InProcessRsus(ros::NodeHandle nh, const std::vector<std::string>& rsu_ids, const std::vector<double>& zones_m,
                int num_lanes, const auth::MessageKey* key);

  /// Each RSU's decision period [steps], for the lockstep's registration.
  std::vector<std::pair<std::string, int>> decisionPeriods() const;

  /// One bridge step: the step's events (null: none published) and states to every RSU in
  /// id order; the RSUs due decide, their cluster states then reach the others (a decision
  /// uses its peers' states of earlier steps only: PeerStates), and what follows each
  /// decision runs (learning starts on its thread). @return the answers, in id order.
  /// @throws std::runtime_error when an RSU cannot serve this road (its lane count).
  std::vector<palcas_msgs::AdvisoryArray> step(const palcas_msgs::VehicleStateArray& states,
                                               const palcas_msgs::VehicleEventArray* events);

  /// Joins the learners; training with a checkpoint directory, the final checkpoints.
  void shutdown();

 private:
  struct Rsu {
    std::unique_ptr<rsu::RsuDecider> decider;
    ros::Publisher status_pub, cluster_pub, submitted_pub, model_pub;
  };
  std::vector<Rsu> rsus_;
  ros::Subscriber version_sub_;  ///< the server's global version, announced to every RSU
};

}  // namespace palcas::bridge
