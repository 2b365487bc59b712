#include "palcas_sumo_bridge/bridge_node.h"

#include <palcas_common/bridge_road.h>
#include <palcas_common/message_auth.h>
#include <palcas_core/metrics/advisory_validator.h>
#include <palcas_msgs/AdvisoryRejection.h>
#include <palcas_msgs/EpisodeMetrics.h>
#include <palcas_msgs/RoadDescription.h>
#include <palcas_msgs/VehicleEventArray.h>
#include <rosgraph_msgs/Clock.h>
#include <ros/callback_queue.h>
#include <tf2_msgs/TFMessage.h>
#include <visualization_msgs/MarkerArray.h>

#include "palcas_sumo_bridge/msg_conversion.h"
#include "palcas_sumo_bridge/run_files.h"
#include "palcas_sumo_bridge/topics.h"

namespace palcas::bridge {

BridgeNode::BridgeNode(ros::NodeHandle nh, ros::NodeHandle private_nh)
    : nh_(nh), private_nh_(private_nh), options_(loadBridgeOptions(private_nh_)),
      sumocfg_path_(prepareScenario(options_)),
      runner_(std::make_unique<sim::EpisodeRunner>(
          runnerOptions(options_),
          [this](int episode) {
            return std::make_unique<sim::SumoSession>(sessionOptionsFor(options_, sumocfg_path_, episode));
          })),
      markers_(std::make_unique<RvizMarkers>(session().laneShapes(), session().road(),
                                             prepareRvizView(options_, session().laneShapes()),
                                             session().rsuPoses())),
      rules_(measureRules(options_, session().road())),
      measure_(std::make_unique<EpisodeMeasure>(rules_)),
      auth_key_(common::loadMessageKey(options_.auth_key_file)) {
  completeManifest(options_, session().sumoVersion(), sim::SumoSession::apiName(), rules_);
  advertise();
  advisories_sub_ = nh_.subscribe(ADVISORIES_TOPIC, 100, &BridgeNode::onAdvisories, this,
                                  ros::TransportHints().tcpNoDelay());
  publishRoad();  // before registration opens: an RSU checks its zone when it registers
  // In process with no RSU (SUMO-native, keep): nothing to run.
  if (options_.inprocess_rsus && !options_.expected_rsus.empty()) startInProcessRsus();
  register_srv_ = nh_.advertiseService(REGISTER_RSU_SERVICE, &BridgeNode::onRegister, this);
  setUpDiagnostics();
  ROS_INFO_NAMED("startup", "palcas bridge: %s (%s), scenario %s, PR %.0f%%, seed %u, %.0f s, %zu RSU(s) expected",
           session().sumoVersion().c_str(), sim::SumoSession::apiName(), sumocfg_path_.c_str(),
           100.0 * options_.scenario.penetration_rate, options_.scenario.seed, options_.scenario.duration_s, options_.expected_rsus.size());
  if (auth_key_)
    ROS_INFO_NAMED("startup", "palcas bridge: advisories authenticated with key %s (fingerprint %s)",
             options_.auth_key_file.c_str(), auth_key_->fingerprint().c_str());
  else if (!options_.expected_rsus.empty() || options_.session.advisory_control)
    ROS_WARN_NAMED("startup", "palcas bridge: ~auth_key_file not set: advisories are NOT authenticated, any "
             "publisher on %s can steer CAVs", ADVISORIES_TOPIC);
}

void BridgeNode::publishRoad() {
  std::vector<double> zones;
  for (const sim::ClusterInfo& c : session().road().clusters()) {
    if (zones.empty()) zones.push_back(c.x_start_m);
    zones.push_back(c.x_end_m);
  }
  nh_.setParam(common::ROAD_ZONES_PARAM, zones);
  nh_.setParam(common::ROAD_LANES_PARAM, session().road().numMainLanes());
  // The same road on a latched topic: a bag of the run then carries it (replay_policy).
  palcas_msgs::RoadDescription road;
  road.header.stamp = ros::Time(session().timeS());
  road.header.frame_id = ROAD_FRAME;
  road.zone_boundaries_m = zones;
  road.num_lanes = static_cast<std::uint8_t>(session().road().numMainLanes());
  road.step_length_s = session().stepLengthS();
  road.scenario_dir = options_.scenario.scenario_dir;
  road_pub_.publish(road);
}

void BridgeNode::startInProcessRsus() {
  std::vector<double> zones;
  for (const sim::ClusterInfo& c : session().road().clusters()) {
    if (zones.empty()) zones.push_back(c.x_start_m);
    zones.push_back(c.x_end_m);
  }
  inprocess_ = std::make_unique<InProcessRsus>(nh_, options_.expected_rsus, zones, session().road().numMainLanes(),
                                               auth_key_.get());
  for (const auto& [id, period] : inprocess_->decisionPeriods()) {
    std::string reason;
    if (!runner_->lockstep().registerRsu(id, &reason, static_cast<std::uint32_t>(period)))
      throw std::runtime_error("in-process RSU '" + id + "' not registered: " + reason);
  }
  ROS_INFO_NAMED("startup", "palcas bridge: %zu RSU(s) in process, answering by call", options_.expected_rsus.size());
}

void BridgeNode::advertise() {
  // Deep outgoing queues: free-running, the bridge can publish thousands of steps per second
  // on a small road, and a recorder must not lose one (the bag must reproduce the metrics).
  states_pub_ = nh_.advertise<palcas_msgs::VehicleStateArray>(VEHICLE_STATES_TOPIC, 5000);
  events_pub_ = nh_.advertise<palcas_msgs::VehicleEventArray>(VEHICLE_EVENTS_TOPIC, 5000);
  metrics_pub_ = nh_.advertise<palcas_msgs::EpisodeMetrics>(EPISODE_METRICS_TOPIC, 10, true);
  rejections_pub_ = nh_.advertise<palcas_msgs::AdvisoryRejection>(ADVISORY_REJECTIONS_TOPIC, 100);
  clock_pub_ = nh_.advertise<rosgraph_msgs::Clock>(CLOCK_TOPIC, 1000);
  markers_pub_ = nh_.advertise<visualization_msgs::MarkerArray>(MARKERS_TOPIC, 2, true);
  tf_pub_ = nh_.advertise<tf2_msgs::TFMessage>(TF_TOPIC, 10);
  road_pub_ = nh_.advertise<palcas_msgs::RoadDescription>(ROAD_DESCRIPTION_TOPIC, 1, true);
  markers_pub_.publish(markers_->roadMarkers(ros::Time(0)));
}

bool BridgeNode::onRegister(palcas_msgs::RegisterRsu::Request& req,
                            palcas_msgs::RegisterRsu::Response& res) {
  std::string reason;
  res.accepted = runner_->lockstep().registerRsu(req.rsu_id, &reason, req.answer_period_steps);
  res.reason = reason;
  res.next_step = session().stepCount();
  if (res.accepted)
    ROS_INFO_NAMED("startup", "palcas bridge: RSU '%s' registered; it answers every %u step(s)", req.rsu_id.c_str(),
                   std::max<std::uint32_t>(req.answer_period_steps, 1));
  else ROS_WARN_NAMED("startup", "palcas bridge: refused registration: %s", reason.c_str());
  return true;
}

bool BridgeNode::waitForPeers() {
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::duration<double>(options_.startup_timeout_s);
  // A registered RSU node subscribed before registering, but on the bridge's side its
  // connection may still be opening, and a state published before it is up never reaches
  // that RSU (with the V2X channel on, a missed early state changes what it hears at its
  // first decision). So wait for the bridge's side too: one link per RSU node, plus
  // min_subscribers (recorders, test nodes). In-process RSUs need no link.
  auto rsu_nodes = [&] {
    return static_cast<std::uint32_t>(
        inprocess_ ? 0 : options_.expected_rsus.size() - runner_->lockstep().unregistered().size());
  };
  auto subscribers_needed = [&] { return static_cast<std::uint32_t>(options_.min_subscribers) + rsu_nodes(); };
  // And the way back: an RSU's first answer, published before the bridge's subscriber has
  // connected to it, is lost, and the bridge waits out the whole lockstep deadline for it (a
  // late step on a slow machine; the journal, 2026-11-29).
  auto answer_links_ready = [&] { return advisories_sub_.getNumPublishers() >= rsu_nodes(); };
  // The view's recorder (record.launch) is its own process: one that connects late misses
  // the first markers and tf (the journal, 2026-11-29).
  const auto markers_needed = static_cast<std::uint32_t>(options_.min_marker_subscribers);
  auto ready = [&] {
    return runner_->lockstep().allRegistered() && states_pub_.getNumSubscribers() >= subscribers_needed() &&
           answer_links_ready() && markers_pub_.getNumSubscribers() >= markers_needed;
  };
  // Publish the clock so nodes on sim time can start; RSUs register once subscribed.
  rosgraph_msgs::Clock clock;
  clock.clock = ros::Time(session().timeS());
  while (ros::ok() && !ready() && std::chrono::steady_clock::now() < deadline) {
    clock_pub_.publish(clock);
    ros::getGlobalCallbackQueue()->callAvailable(ros::WallDuration(0.05));
  }
  auto warnIfShort = [&](const ros::Publisher& pub, std::uint32_t needed, const char* topic) {
    if (pub.getNumSubscribers() < needed)
      ROS_WARN_NAMED("startup", "palcas bridge: starting with %u of %u expected subscribers of %s after %.1f s",
                     pub.getNumSubscribers(), needed, topic, options_.startup_timeout_s);
  };
  warnIfShort(states_pub_, subscribers_needed(), VEHICLE_STATES_TOPIC);
  warnIfShort(markers_pub_, markers_needed, MARKERS_TOPIC);
  if (!answer_links_ready())
    ROS_WARN_NAMED("startup", "palcas bridge: starting with %u of %u registered RSU nodes' %s connected after %.1f s",
                   advisories_sub_.getNumPublishers(), rsu_nodes(), ADVISORIES_TOPIC, options_.startup_timeout_s);
  if (runner_->lockstep().allRegistered()) return true;
  std::string missing;
  for (const std::string& id : runner_->lockstep().unregistered()) missing += " " + id;
  ROS_WARN_NAMED("startup", "palcas bridge: starting without RSU(s)%s: not registered after %.1f s; they are "
           "waited for once they answer",
           missing.c_str(), options_.startup_timeout_s);
  return false;
}

bool BridgeNode::running() const { return ros::ok(); }

void BridgeNode::publishStep(const sim::SumoSession& session) {
  const ros::Time stamp(session.timeS());
  const std::uint64_t step = session.stepCount();
  rosgraph_msgs::Clock clock;
  clock.clock = stamp;
  clock_pub_.publish(clock);

  current_states_.header.stamp = stamp;
  current_states_.header.frame_id = ROAD_FRAME;
  current_states_.step = step;
  current_states_.step_length_s = session.stepLengthS();
  current_states_.num_lanes = static_cast<uint8_t>(session.road().numMainLanes());
  current_states_.vehicles.clear();
  for (const sim::VehicleRecord& v : session.vehicles()) current_states_.vehicles.push_back(toMsg(v));
  // Measure from the published state only, so a bag of the episode reproduces it. The
  // events of a step go out before its states: on every step with events, and (empty) on
  // every step an RSU may decide on. An RSU decides a step only once it holds that step's
  // array (palcas_rsu's DecisionInputs), since the bridge does not wait for it between its
  // decisions; on one topic the arrays arrive in order, so the earlier ones are in too.
  const auto& sim_events = session.lastEvents();
  const std::vector<metrics::VehicleEvent> events = measure_->onStep(
      current_states_, {sim_events.collided, sim_events.teleported, sim_events.arrived});
  palcas_msgs::VehicleEventArray events_msg;
  const bool events_out = !events.empty() || runner_->lockstep().mayDecideOnOpenStep();
  if (events_out) {
    events_msg.header.stamp = stamp;
    events_msg.header.frame_id = ROAD_FRAME;
    events_msg.step = step;
    for (const auto& e : events) events_msg.events.push_back(toMsg(e));
    events_pub_.publish(events_msg);
  }
  states_pub_.publish(current_states_);
  if (inprocess_)
    for (const palcas_msgs::AdvisoryArray& answer : inprocess_->step(current_states_, events_out ? &events_msg : nullptr))
      accept(answer);
  if (options_.publish_tf && tf_pub_.getNumSubscribers() > 0)
    tf_pub_.publish(markers_->transforms(stamp, session.vehicles()));
}

void BridgeNode::receive(std::chrono::steady_clock::time_point deadline, const std::function<bool()>& done) {
  ros::CallbackQueue* queue = ros::getGlobalCallbackQueue();
  queue->callAvailable();
  while (ros::ok() && !done() && std::chrono::steady_clock::now() < deadline)
    queue->callAvailable(ros::WallDuration(0.0005));
}

void BridgeNode::onAdvisories(const ros::MessageEvent<const palcas_msgs::AdvisoryArray>& event) {
  const palcas_msgs::AdvisoryArray::ConstPtr msg = event.getConstMessage();
  // Checked before the lockstep sees the array: a forged one can neither count as its RSU's
  // answer nor displace the genuine one.
  const auth::Verdict verdict = common::verifyMessage(*msg, auth_key_.get());
  if (verdict != auth::Verdict::kAuthentic) {
    reject(msg->rsu_id, "", palcas_msgs::AdvisoryRejection::UNAUTHENTICATED,
           std::string(auth::verdictName(verdict)) + ": array of " +
               std::to_string(msg->advisories.size()) + " advisories for step " +
               std::to_string(msg->step) + " published by " + event.getPublisherName());
    return;
  }
  accept(*msg);
}

void BridgeNode::accept(const palcas_msgs::AdvisoryArray& msg) {
  auto array = std::make_shared<sim::AdviceArray>();
  array->rsu_id = msg.rsu_id;
  array->step = msg.step;
  array->decision_ms = msg.decision_ms;
  array->advisories.reserve(msg.advisories.size());
  for (const palcas_msgs::Advisory& a : msg.advisories) array->advisories.push_back(toRequest(a, msg.step, msg.rsu_id));
  const sim::EpisodeRunner::AnswerOutcome outcome = runner_->onAnswer(std::move(array));
  for (const std::string& id : outcome.revived)
    ROS_WARN_NAMED("lockstep", "palcas bridge: RSU '%s' answers again (step %lu): waited for from the next step "
             "on", id.c_str(), static_cast<unsigned long>(msg.step));
  if (outcome.verdict == sim::EpisodeRunner::Verdict::kDuplicate)
    ROS_WARN_THROTTLE_NAMED(5.0, "lockstep", "palcas bridge: second answer of RSU '%s' for step %lu ignored",
                      msg.rsu_id.c_str(), static_cast<unsigned long>(msg.step));
  if (outcome.verdict == sim::EpisodeRunner::Verdict::kUnknownRsu)
    ROS_WARN_THROTTLE_NAMED(5.0, "lockstep", "palcas bridge: advisories from unknown RSU '%s' ignored "
                      "(not in ~expected_rsus)", msg.rsu_id.c_str());
}

void BridgeNode::lockstepMissed(std::uint64_t step, const std::vector<std::string>& late,
                                const std::vector<std::string>& newly_lost) {
  if (!late.empty()) {
    measure_->metrics().addLateRsuStep();
    std::string names;
    for (const std::string& id : late) names += " " + id;
    ROS_DEBUG_NAMED("lockstep", "palcas bridge: step %lu: late:%s", static_cast<unsigned long>(step), names.c_str());
    ROS_WARN_THROTTLE_NAMED(5.0, "lockstep", "palcas bridge: step %lu: RSU(s)%s missed the %.3f s deadline; their "
                      "CAVs keep their speed (%lu late steps so far)",
                      static_cast<unsigned long>(step), names.c_str(), options_.lockstep_deadline_s,
                      static_cast<unsigned long>(runner_->lockstep().lateSteps()));
  }
  for (const std::string& id : newly_lost)
    ROS_ERROR_NAMED("lockstep", "palcas bridge: RSU '%s' lost after %d missed steps; continuing without it until "
              "it answers again", id.c_str(), options_.lost_after_missed_steps);
}

void BridgeNode::rejected(const std::string& rsu_id, const std::string& vehicle_id,
                          metrics::RejectionReason reason, const std::string& detail) {
  reject(rsu_id, vehicle_id, static_cast<int>(reason), detail);
}

void BridgeNode::reject(const std::string& rsu_id, const std::string& vehicle_id, int reason,
                        const std::string& detail) {
  measure_->metrics().addAdvisoryRejected(static_cast<metrics::RejectionReason>(reason));
  palcas_msgs::AdvisoryRejection r;
  r.header.stamp = ros::Time(session().timeS());
  r.step = session().stepCount();
  r.rsu_id = rsu_id;
  r.vehicle_id = vehicle_id;
  r.reason = static_cast<uint8_t>(reason);
  r.detail = detail;
  rejections_pub_.publish(r);
  ROS_DEBUG_NAMED("advice", "palcas bridge: step %lu: rejected advisory from '%s' for '%s': %s (%s)",
                  static_cast<unsigned long>(r.step), rsu_id.c_str(), vehicle_id.c_str(),
                  metrics::rejectionReasonName(static_cast<metrics::RejectionReason>(reason)).c_str(), detail.c_str());
  // The guard declines advice in every run with busy zones: expected, not a fault to warn of.
  if (metrics::isGuardRefusal(static_cast<metrics::RejectionReason>(reason))) return;
  ROS_WARN_THROTTLE_NAMED(2.0, "advice", "palcas bridge: rejected advisory from '%s' for '%s': %s (%s)",
                    rsu_id.c_str(), vehicle_id.c_str(),
                    metrics::rejectionReasonName(static_cast<metrics::RejectionReason>(reason)).c_str(),
                    detail.c_str());
}

void BridgeNode::applied(const std::string& vehicle_id) {
  measure_->metrics().addAdvisoriesApplied();
  ROS_DEBUG_NAMED("advice", "palcas bridge: step %lu: advisory for '%s' carried out",
                  static_cast<unsigned long>(session().stepCount()), vehicle_id.c_str());
}

void BridgeNode::actuated(const sim::SumoSession& session, const sim::AdvisoryHolds& holds) {
  if (session.stepCount() % static_cast<std::uint64_t>(options_.markers_every_steps) != 0 ||
      markers_pub_.getNumSubscribers() == 0)
    return;
  // Every advisory in force, not only this step's: RSUs decide once a second, the markers
  // go out every few steps, and an arrow should stay while its command holds.
  markers_pub_.publish(markers_->dynamicMarkers(ros::Time(session.timeS()), session.vehicles(), holds.inForce()));
}

void BridgeNode::stepped(const sim::SumoSession&) {
  diagnostics_.update();  // at most once per ~diagnostic_period (1 s of simulated time)
}

void BridgeNode::startEpisode(int episode) {
  episode_ = episode;
  runner_->startEpisode(episode);
  measure_ = std::make_unique<EpisodeMeasure>(rules_);
}

void BridgeNode::writeEpisode(int episode, const sim::EpisodeRun& run) {
  RunSummary summary;
  summary.episode = episode;
  summary.metrics = measure_->metrics().snapshot();
  summary.exits = measure_->cavExits();
  summary.wall_seconds = run.wall_s;
  summary.steps = run.steps;
  summary.late_by_rsu = run.late_by_rsu;
  for (int r = 0; r < metrics::REJECTION_REASON_COUNT; ++r)
    summary.rejections_by_reason[metrics::rejectionReasonName(static_cast<metrics::RejectionReason>(r))] =
        measure_->metrics().rejections(static_cast<metrics::RejectionReason>(r));
  summary.timing = run.timing;
  summary.decision_ms = run.decision_ms;
  summary.lane_changes_done = session().laneChangesDone();
  summary.lane_changes_dropped = session().laneChangesDropped();
  summary.vanished_vehicles = session().vanishedVehicles();
  summary.route_changes_failed = session().routeChangesFailed();
  summary.guard = session().guardCounters();
  summary.insertion_dropped = session().insertionDropped();
  summary.insertion_waiting_end = session().insertionWaiting();
  summary.insertion_wait_veh_s = session().insertionWaitVehicleSeconds();
  summary.downlink = run.downlink;
  writeMetricsJson(options_, summary, episode);
  ROS_INFO_NAMED("episode", "palcas bridge: episode %d/%d done: %.0f s simulated in %.1f s; results in %s", episode + 1,
           options_.first_episode + options_.episodes, session().timeS(), summary.wall_seconds, options_.out_dir.c_str());
}

int BridgeNode::run() {
  waitForPeers();
  const int first = options_.first_episode;
  episode_ = first;
  if (first > 0) startEpisode(first);  // a resumed training: seed + first, as numbered
  for (int episode = first; episode < first + options_.episodes && ros::ok(); ++episode) {
    if (episode > first) startEpisode(episode);
    writeEpisode(episode, runner_->runEpisode(episode, *this));
  }
  if (inprocess_) inprocess_->shutdown();  // final checkpoints of a training
  // Stay up a moment: recorders and RSUs still have the last messages in flight.
  const auto linger_end = std::chrono::steady_clock::now() + std::chrono::duration<double>(options_.linger_s);
  while (ros::ok() && std::chrono::steady_clock::now() < linger_end)
    ros::getGlobalCallbackQueue()->callAvailable(ros::WallDuration(0.05));
  return 0;
}

}  // namespace palcas::bridge
