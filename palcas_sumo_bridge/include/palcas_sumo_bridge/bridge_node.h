#pragma once
// The SUMO bridge node: ROS wiring around palcas_sim::EpisodeRunner (the ROS-free episode
// loop: lockstep, advisory check, actuation, pacing) and the episode's measurement. The node
// publishes each step, measures it, receives and authenticates the RSUs' answers, serves
// registration, markers, tf and diagnostics, and writes each episode's metrics. With
// ~inprocess_rsus the RSUs run inside it (inprocess_rsus.h) and answer each step by call.

#include <diagnostic_updater/diagnostic_updater.h>
#include <palcas_core/common/message_auth.h>
#include <palcas_msgs/AdvisoryArray.h>
#include <palcas_msgs/RegisterRsu.h>
#include <palcas_msgs/VehicleStateArray.h>
#include <ros/ros.h>

#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "palcas_sim/episode_runner.h"
#include "palcas_sumo_bridge/bridge_options.h"
#include "palcas_sumo_bridge/episode_measure.h"
#include "palcas_sumo_bridge/inprocess_rsus.h"
#include "palcas_sumo_bridge/run_files.h"
#include "palcas_sumo_bridge/rviz_markers.h"

namespace palcas::bridge {

class BridgeNode : private sim::EpisodePort {
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
  void writeEpisode(int episode, const sim::EpisodeRun& run);
  void onAdvisories(const ros::MessageEvent<const palcas_msgs::AdvisoryArray>& event);
  /// An authentic answer (from the topic or an in-process RSU) to the episode runner.
  void accept(const palcas_msgs::AdvisoryArray& msg);
  /// ~inprocess_rsus: builds the RSUs in this process and registers them with the lockstep.
  void startInProcessRsus();
  bool onRegister(palcas_msgs::RegisterRsu::Request& req, palcas_msgs::RegisterRsu::Response& res);
  void reject(const std::string& rsu_id, const std::string& vehicle_id, int reason,
              const std::string& detail);
  /// /diagnostics: the lockstep, the simulation and the advice guard (bridge_diagnostics.h).
  void setUpDiagnostics();
  void diagnoseLockstep(diagnostic_updater::DiagnosticStatusWrapper& s);
  void diagnoseSimulation(diagnostic_updater::DiagnosticStatusWrapper& s);
  void diagnoseGuard(diagnostic_updater::DiagnosticStatusWrapper& s);

  // sim::EpisodePort: the episode loop's transport over ROS.
  bool running() const override;
  void publishStep(const sim::SumoSession& session) override;
  void receive(std::chrono::steady_clock::time_point deadline, const std::function<bool()>& done) override;
  void lockstepMissed(std::uint64_t step, const std::vector<std::string>& late,
                      const std::vector<std::string>& newly_lost) override;
  void rejected(const std::string& rsu_id, const std::string& vehicle_id, metrics::RejectionReason reason,
                const std::string& detail) override;
  void applied(const std::string& vehicle_id) override;
  void actuated(const sim::SumoSession& session, const sim::AdvisoryHolds& holds) override;
  void stepped(const sim::SumoSession& session) override;
  void progress(const sim::SumoSession& session) override;

  const sim::SumoSession& session() const { return runner_->session(); }

  ros::NodeHandle nh_, private_nh_;
  BridgeOptions options_;
  std::string sumocfg_path_;
  std::unique_ptr<sim::EpisodeRunner> runner_;  ///< owns SUMO, the lockstep and the advice's way
  std::unique_ptr<RvizMarkers> markers_;
  MeasureRules rules_;
  std::unique_ptr<EpisodeMeasure> measure_;
  std::unique_ptr<auth::MessageKey> auth_key_;  ///< null: advisories are not authenticated
  std::unique_ptr<InProcessRsus> inprocess_;    ///< null: RSU nodes answer over topics
  int episode_ = 0;

  ros::Publisher states_pub_, events_pub_, metrics_pub_, rejections_pub_, clock_pub_,
      markers_pub_, tf_pub_, road_pub_;
  ros::Subscriber advisories_sub_;
  ros::ServiceServer register_srv_;

  palcas_msgs::VehicleStateArray current_states_;
  diagnostic_updater::Updater diagnostics_;
  std::uint64_t late_steps_reported_ = 0;  ///< lockstep late steps at the last diagnostics report
};

}  // namespace palcas::bridge
