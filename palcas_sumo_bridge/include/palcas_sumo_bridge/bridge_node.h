#pragma once
// The SUMO bridge node: a thin ROS shell around palcas_sim::SumoSession and palcas_core's
// outcome tracker, metrics accumulator and advisory validator. One simulation step per
// loop iteration: publish the state of step k, wait (lockstep) for the RSUs' advisories
// for step k, apply them, advance SUMO to step k+1, measure.

#include <diagnostic_updater/diagnostic_updater.h>
#include <palcas_core/common/message_auth.h>
#include <palcas_msgs/AdvisoryArray.h>
#include <palcas_msgs/RegisterRsu.h>
#include <palcas_msgs/VehicleStateArray.h>
#include <ros/ros.h>

#include <chrono>
#include <map>
#include <memory>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "palcas_sim/advisory_holds.h"
#include "palcas_sim/lockstep.h"
#include "palcas_sim/run_recorder.h"
#include "palcas_sim/sumo_session.h"
#include "palcas_sumo_bridge/bridge_options.h"
#include "palcas_sumo_bridge/episode_measure.h"
#include "palcas_sumo_bridge/run_files.h"
#include "palcas_sumo_bridge/rviz_markers.h"

namespace palcas::bridge {

class BridgeNode {
 public:
  /// Loads options, generates the scenario into the run folder, starts SUMO, advertises,
  /// subscribes and offers services. @throws std::exception naming what failed.
  BridgeNode(ros::NodeHandle nh, ros::NodeHandle private_nh);

  /// Runs every episode to its duration (or until ROS shuts down), writing each one's
  /// metrics. @return the process exit code.
  int run();

 private:
  void advertise();
  /// ROAD_ZONES_PARAM and ROAD_LANES_PARAM: this road's zones and lanes for the RSUs' check.
  void publishRoad();
  /// Start handshake: every expected RSU registered and ~min_subscribers listening, or
  /// the startup timeout. @return false when some RSU did not register.
  bool waitForPeers();
  /// Episode k >= 1: SUMO reloaded with seed + k, measuring and advisory state reset.
  void startEpisode(int episode);
  void runEpisode(int episode);
  void publishStep();
  void waitForAdvisories();
  void applyAdvisories();
  void publishMetrics();
  void onAdvisories(const ros::MessageEvent<const palcas_msgs::AdvisoryArray>& event);
  bool onRegister(palcas_msgs::RegisterRsu::Request& req, palcas_msgs::RegisterRsu::Response& res);
  void reject(const std::string& rsu_id, const std::string& vehicle_id, int reason,
              const std::string& detail);
  double wallSeconds() const;
  /// /diagnostics: the lockstep, the simulation and the advice guard (bridge_diagnostics.h).
  void setUpDiagnostics();
  void diagnoseLockstep(diagnostic_updater::DiagnosticStatusWrapper& s);
  void diagnoseSimulation(diagnostic_updater::DiagnosticStatusWrapper& s);
  void diagnoseGuard(diagnostic_updater::DiagnosticStatusWrapper& s);

  ros::NodeHandle nh_, private_nh_;
  BridgeOptions options_;
  std::string sumocfg_path_;
  std::unique_ptr<sim::SumoSession> session_;
  std::unique_ptr<sim::Lockstep> lockstep_;
  std::unique_ptr<RvizMarkers> markers_;
  MeasureRules rules_;
  std::unique_ptr<EpisodeMeasure> measure_;
  std::unique_ptr<sim::RunRecorder> recorder_;  ///< trajectories.csv + decisions.csv, if asked
  std::unique_ptr<auth::MessageKey> auth_key_;  ///< null: advisories are not authenticated
  int episode_ = 0;

  ros::Publisher states_pub_, events_pub_, metrics_pub_, rejections_pub_, clock_pub_,
      markers_pub_, tf_pub_, road_pub_;
  ros::Subscriber advisories_sub_;
  ros::ServiceServer register_srv_;

  palcas_msgs::VehicleStateArray current_states_;
  /// Advisory arrays received for the open step, by RSU, in arrival order.
  std::vector<palcas_msgs::AdvisoryArray::ConstPtr> pending_;
  /// One advisory on its way to its CAV (the V2X channel's downlink).
  struct AdviceInFlight {
    palcas_msgs::AdvisoryArray::ConstPtr array;
    std::size_t index = 0;
  };
  v2x::Channel channel_;
  v2x::DelayLine<AdviceInFlight> downlink_;
  v2x::DownlinkCounts downlink_counts_;
  /// The advisories that reach their CAVs this step: every one of pending_ with the channel
  /// off; through latency, loss, range and max age with it on (counted in downlink_counts_).
  std::vector<AdviceInFlight> deliverAdvisories(std::uint64_t step);
  /// Where RSU `rsu_id` stands along the road (its zone's centre) [m]; NaN for one without
  /// a zone (the centralized baseline): no range applies to it.
  double rsuPositionM(const std::string& rsu_id) const;
  /// Who advised each CAV last and when: its command holds for advisory_hold_steps,
  /// unless that RSU is late, then its own driving takes over.
  sim::AdvisoryHolds holds_;
  std::unordered_set<std::string> late_this_step_;
  std::map<std::string, std::uint64_t> late_by_rsu_;
  std::vector<float> decision_ms_;  ///< this episode's RSU decision latencies [ms]
  std::chrono::steady_clock::time_point wall_start_;
  double next_metrics_s_ = 0.0;
  diagnostic_updater::Updater diagnostics_;
  std::uint64_t late_steps_reported_ = 0;  ///< lockstep late steps at the last diagnostics report
};

}  // namespace palcas::bridge
