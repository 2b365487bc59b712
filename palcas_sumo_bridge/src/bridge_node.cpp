#include "palcas_sumo_bridge/bridge_node.h"

#include <algorithm>
#include <limits>
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

#include <cmath>
#include <thread>

#include "palcas_sumo_bridge/bridge_diagnostics.h"
#include "palcas_sumo_bridge/msg_conversion.h"
#include "palcas_sumo_bridge/run_files.h"
#include "palcas_sumo_bridge/topics.h"

namespace palcas::bridge {
namespace {

MeasureRules measureRules(const BridgeOptions& o, const sim::RoadLayout& road) {
  MeasureRules rules;
  for (const sim::ClusterInfo& c : road.clusters())
    rules.tracker.exit_x_m.push_back(c.off_ramp_edge.empty() ? road.mainlineLengthM() : c.exit_x_m);
  rules.tracker.miss_margin_m = o.exit_miss_margin_m;
  rules.tracker.stop_speed_mps = o.merge_stop_speed_mps;
  rules.tracker.stop_window_m = o.merge_stop_window_m;
  rules.metrics.comfort_accel_mps2 = o.comfort_threshold_mps2;
  return rules;
}

}  // namespace

BridgeNode::BridgeNode(ros::NodeHandle nh, ros::NodeHandle private_nh)
    : nh_(nh), private_nh_(private_nh), options_(loadBridgeOptions(private_nh_)),
      sumocfg_path_(prepareScenario(options_)),
      session_(std::make_unique<sim::SumoSession>(sessionOptionsFor(options_, sumocfg_path_))),
      lockstep_(std::make_unique<sim::Lockstep>(options_.expected_rsus,
                                                options_.lost_after_missed_steps)),
      markers_(std::make_unique<RvizMarkers>(session_->laneShapes(), session_->road(),
                                             prepareRvizView(options_, session_->laneShapes()))),
      rules_(measureRules(options_, session_->road())),
      measure_(std::make_unique<EpisodeMeasure>(rules_)),
      auth_key_(common::loadMessageKey(options_.auth_key_file)),
      channel_(options_.v2x, options_.scenario.step_length_s),
      holds_(static_cast<std::uint64_t>(options_.advisory_hold_steps)) {
  completeManifest(options_, session_->sumoVersion(), sim::SumoSession::apiName(), rules_);
  advertise();
  advisories_sub_ = nh_.subscribe(ADVISORIES_TOPIC, 100, &BridgeNode::onAdvisories, this,
                                  ros::TransportHints().tcpNoDelay());
  publishRoad();  // before registration opens: an RSU checks its zone when it registers
  register_srv_ = nh_.advertiseService(REGISTER_RSU_SERVICE, &BridgeNode::onRegister, this);
  setUpDiagnostics();
  ROS_INFO("palcas bridge: %s (%s), scenario %s, PR %.0f%%, seed %u, %.0f s, %zu RSU(s) expected",
           session_->sumoVersion().c_str(), sim::SumoSession::apiName(), sumocfg_path_.c_str(),
           100.0 * options_.scenario.penetration_rate, options_.scenario.seed, options_.scenario.duration_s, options_.expected_rsus.size());
  if (auth_key_)
    ROS_INFO("palcas bridge: advisories authenticated with key %s (fingerprint %s)",
             options_.auth_key_file.c_str(), auth_key_->fingerprint().c_str());
  else if (!options_.expected_rsus.empty() || options_.session.advisory_control)
    ROS_WARN("palcas bridge: ~auth_key_file not set: advisories are NOT authenticated, any "
             "publisher on %s can steer CAVs", ADVISORIES_TOPIC);
}

void BridgeNode::publishRoad() {
  std::vector<double> zones;
  for (const sim::ClusterInfo& c : session_->road().clusters()) {
    if (zones.empty()) zones.push_back(c.x_start_m);
    zones.push_back(c.x_end_m);
  }
  nh_.setParam(common::ROAD_ZONES_PARAM, zones);
  nh_.setParam(common::ROAD_LANES_PARAM, session_->road().numMainLanes());
  // The same road on a latched topic: a bag of the run then carries it (replay_policy).
  palcas_msgs::RoadDescription road;
  road.header.stamp = ros::Time(session_->timeS());
  road.header.frame_id = MAP_FRAME;
  road.zone_boundaries_m = zones;
  road.num_lanes = static_cast<std::uint8_t>(session_->road().numMainLanes());
  road.step_length_s = session_->stepLengthS();
  road.scenario_dir = options_.scenario.scenario_dir;
  road_pub_.publish(road);
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
  res.accepted = lockstep_->registerRsu(req.rsu_id, &reason);
  res.reason = reason;
  res.next_step = session_->stepCount();
  if (res.accepted) ROS_INFO("palcas bridge: RSU '%s' registered", req.rsu_id.c_str());
  else ROS_WARN("palcas bridge: refused registration: %s", reason.c_str());
  return true;
}

bool BridgeNode::waitForPeers() {
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::duration<double>(options_.startup_timeout_s);
  auto ready = [&] {
    return lockstep_->allRegistered() &&
           states_pub_.getNumSubscribers() >= static_cast<std::uint32_t>(options_.min_subscribers);
  };
  // Publish the clock so nodes on sim time can start; RSUs register once subscribed.
  rosgraph_msgs::Clock clock;
  clock.clock = ros::Time(session_->timeS());
  while (ros::ok() && !ready() && std::chrono::steady_clock::now() < deadline) {
    clock_pub_.publish(clock);
    ros::getGlobalCallbackQueue()->callAvailable(ros::WallDuration(0.05));
  }
  if (states_pub_.getNumSubscribers() < static_cast<std::uint32_t>(options_.min_subscribers))
    ROS_WARN("palcas bridge: starting with %u of %d expected subscribers of %s after %.1f s",
             states_pub_.getNumSubscribers(), options_.min_subscribers, VEHICLE_STATES_TOPIC,
             options_.startup_timeout_s);
  if (lockstep_->allRegistered()) return true;
  std::string missing;
  for (const std::string& id : lockstep_->unregistered()) missing += " " + id;
  ROS_WARN("palcas bridge: starting without RSU(s)%s: not registered after %.1f s; they are "
           "waited for once they answer",
           missing.c_str(), options_.startup_timeout_s);
  return false;
}

double BridgeNode::wallSeconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start_).count();
}

void BridgeNode::publishStep() {
  const ros::Time stamp(session_->timeS());
  const std::uint64_t step = session_->stepCount();
  rosgraph_msgs::Clock clock;
  clock.clock = stamp;
  clock_pub_.publish(clock);

  current_states_.header.stamp = stamp;
  current_states_.header.frame_id = MAP_FRAME;
  current_states_.step = step;
  current_states_.step_length_s = session_->stepLengthS();
  current_states_.num_lanes = static_cast<uint8_t>(session_->road().numMainLanes());
  current_states_.vehicles.clear();
  for (const sim::VehicleRecord& v : session_->vehicles()) current_states_.vehicles.push_back(toMsg(v));
  // Measure from the published state only, so a bag of the episode reproduces it. The
  // events of a step go out before its states: an RSU then usually has them when it
  // decides (it does not rely on it: see RsuController's limbo).
  const auto& sim_events = session_->lastEvents();
  const std::vector<metrics::VehicleEvent> events = measure_->onStep(
      current_states_, {sim_events.collided, sim_events.teleported, sim_events.arrived});
  if (!events.empty()) {
    palcas_msgs::VehicleEventArray msg;
    msg.header.stamp = stamp;
    msg.header.frame_id = MAP_FRAME;
    msg.step = step;
    for (const auto& e : events) msg.events.push_back(toMsg(e));
    events_pub_.publish(msg);
  }
  lockstep_->beginStep(step);
  states_pub_.publish(current_states_);
  if (options_.publish_tf && tf_pub_.getNumSubscribers() > 0)
    tf_pub_.publish(markers_->transforms(stamp, session_->vehicles()));
}

void BridgeNode::onAdvisories(const ros::MessageEvent<const palcas_msgs::AdvisoryArray>& event) {
  const palcas_msgs::AdvisoryArray::ConstPtr msg = event.getConstMessage();
  // Checked before lockstep sees the array: a forged one can neither count as its RSU's
  // answer nor displace the genuine one.
  const auth::Verdict verdict = common::verifyMessage(*msg, auth_key_.get());
  if (verdict != auth::Verdict::kAuthentic) {
    reject(msg->rsu_id, "", palcas_msgs::AdvisoryRejection::UNAUTHENTICATED,
           std::string(auth::verdictName(verdict)) + ": array of " +
               std::to_string(msg->advisories.size()) + " advisories for step " +
               std::to_string(msg->step) + " published by " + event.getPublisherName());
    return;
  }
  if (!lockstep_->enabled()) {
    pending_.push_back(msg);  // free-running: every publisher may advise
    return;
  }
  const sim::Lockstep::Answer answer = lockstep_->onAnswer(msg->rsu_id, msg->step);
  for (const std::string& id : lockstep_->takeRevived())
    ROS_WARN("palcas bridge: RSU '%s' answers again (step %lu): waited for from the next step "
             "on", id.c_str(), static_cast<unsigned long>(msg->step));
  switch (answer) {
    case sim::Lockstep::Answer::kAccepted:
      pending_.push_back(msg);
      break;
    case sim::Lockstep::Answer::kStale:
      // Too late for lockstep, but the validator decides whether its age is acceptable.
      pending_.push_back(msg);
      break;
    case sim::Lockstep::Answer::kDuplicate:
      ROS_WARN_THROTTLE(5.0, "palcas bridge: second answer of RSU '%s' for step %lu ignored",
                        msg->rsu_id.c_str(), static_cast<unsigned long>(msg->step));
      break;
    case sim::Lockstep::Answer::kUnknownRsu:
      ROS_WARN_THROTTLE(5.0, "palcas bridge: advisories from unknown RSU '%s' ignored "
                        "(not in ~expected_rsus)", msg->rsu_id.c_str());
      break;
  }
}

void BridgeNode::waitForAdvisories() {
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::duration<double>(options_.lockstep_deadline_s);
  ros::CallbackQueue* queue = ros::getGlobalCallbackQueue();
  queue->callAvailable();
  while (ros::ok() && !lockstep_->complete() && std::chrono::steady_clock::now() < deadline)
    queue->callAvailable(ros::WallDuration(0.0005));
  std::vector<std::string> newly_lost;
  const std::vector<std::string> late = lockstep_->endStep(&newly_lost);
  late_this_step_ = std::unordered_set<std::string>(late.begin(), late.end());
  for (const std::string& id : lockstep_->lostRsus()) late_this_step_.insert(id);
  if (!late.empty()) {
    measure_->metrics().addLateRsuStep();
    std::string names;
    for (const std::string& id : late) {
      names += " " + id;
      ++late_by_rsu_[id];
    }
    ROS_WARN_THROTTLE(5.0, "palcas bridge: step %lu: RSU(s)%s missed the %.3f s deadline; their "
                      "CAVs keep their speed (%lu late steps so far)",
                      static_cast<unsigned long>(session_->stepCount()), names.c_str(),
                      options_.lockstep_deadline_s,
                      static_cast<unsigned long>(lockstep_->lateSteps()));
  }
  for (const std::string& id : newly_lost)
    ROS_ERROR("palcas bridge: RSU '%s' lost after %d missed steps; continuing without it until "
              "it answers again", id.c_str(), options_.lost_after_missed_steps);
}

void BridgeNode::reject(const std::string& rsu_id, const std::string& vehicle_id, int reason,
                        const std::string& detail) {
  measure_->metrics().addAdvisoryRejected(static_cast<metrics::RejectionReason>(reason));
  palcas_msgs::AdvisoryRejection r;
  r.header.stamp = ros::Time(session_->timeS());
  r.step = session_->stepCount();
  r.rsu_id = rsu_id;
  r.vehicle_id = vehicle_id;
  r.reason = static_cast<uint8_t>(reason);
  r.detail = detail;
  rejections_pub_.publish(r);
  ROS_WARN_THROTTLE(2.0, "palcas bridge: rejected advisory from '%s' for '%s': %s (%s)",
                    rsu_id.c_str(), vehicle_id.c_str(),
                    metrics::rejectionReasonName(static_cast<metrics::RejectionReason>(reason)).c_str(),
                    detail.c_str());
}

double BridgeNode::rsuPositionM(const std::string& rsu_id) const {
  const auto& clusters = session_->road().clusters();
  if (rsu_id.rfind("rsu_", 0) != 0 || rsu_id.size() == 4 ||
      rsu_id.find_first_not_of("0123456789", 4) != std::string::npos)
    return std::numeric_limits<double>::quiet_NaN();
  const std::size_t k = std::stoul(rsu_id.substr(4));
  if (k >= clusters.size()) return std::numeric_limits<double>::quiet_NaN();
  return 0.5 * (clusters[k].x_start_m + clusters[k].x_end_m);
}

std::vector<BridgeNode::AdviceInFlight> BridgeNode::deliverAdvisories(std::uint64_t step) {
  std::vector<AdviceInFlight> arrived;
  for (const auto& array : pending_)
    for (std::size_t i = 0; i < array->advisories.size(); ++i) {
      ++downlink_counts_.sent;
      if (!channel_.enabled()) {
        ++downlink_counts_.delivered;
        arrived.push_back({array, i});
        continue;
      }
      const v2x::Delivery d =
          channel_.transmit(v2x::MessageClass::ADVISORY, array->rsu_id, array->advisories[i].vehicle_id, array->step);
      if (d.lost) ++downlink_counts_.lost;
      else downlink_.push(array->step + d.delay_steps, {array, i});
    }
  if (!channel_.enabled()) return arrived;
  const std::uint64_t max_age = channel_.stepsWithin(channel_.params().max_advice_age_s);
  for (AdviceInFlight& in : downlink_.release(step)) {
    const std::uint64_t age = step >= in.array->step ? step - in.array->step : 0;
    if (age > max_age) {
      ++downlink_counts_.too_old;
      continue;
    }
    // Range when it arrives: a CAV that drove out of its RSU's reach does not hear it.
    const sim::VehicleRecord* vehicle = session_->find(in.array->advisories[in.index].vehicle_id);
    const double rsu_x = rsuPositionM(in.array->rsu_id);
    if (vehicle && !std::isnan(rsu_x) && !channel_.inRange(rsu_x, vehicle->x_m)) {
      ++downlink_counts_.out_of_range;
      continue;
    }
    ++downlink_counts_.delivered;
    if (age > 0) ++downlink_counts_.late;
    downlink_counts_.delivered_age_sum_s += static_cast<double>(age) * channel_.stepLengthS();
    arrived.push_back(std::move(in));
  }
  // Arrival order over ROS differs between runs; two RSUs may advise one CAV at once (stale
  // states put it in both zones). The newest decision wins, then the lower RSU id: the same
  // every run (the others are rejected as duplicates).
  std::stable_sort(arrived.begin(), arrived.end(), [](const AdviceInFlight& a, const AdviceInFlight& b) {
    if (a.array->step != b.array->step) return a.array->step > b.array->step;
    if (a.array->rsu_id != b.array->rsu_id) return a.array->rsu_id < b.array->rsu_id;
    return a.index < b.index;
  });
  return arrived;
}

void BridgeNode::applyAdvisories() {
  ros::getGlobalCallbackQueue()->callAvailable();
  metrics::AdvisoryLimits limits;
  limits.max_step_age = static_cast<std::uint64_t>(options_.max_advisory_age_steps);
  // Advice the channel delayed answers an earlier step: as old as the channel allows.
  if (channel_.enabled())
    limits.max_step_age = std::max(limits.max_step_age, channel_.stepsWithin(channel_.params().max_advice_age_s));
  const std::uint64_t step = session_->stepCount();
  const int lanes = session_->road().numMainLanes();
  std::unordered_set<std::string> advised;
  for (const auto& array : pending_)
    if (!array->advisories.empty()) {
      decision_ms_.push_back(array->decision_ms);
      if (recorder_)
        recorder_->addDecision(session_->timeS(), array->rsu_id, array->decision_ms,
                               array->advisories.size());
    }
  {
    for (const AdviceInFlight& in : deliverAdvisories(step)) {
      const auto& array = in.array;
      const palcas_msgs::Advisory& a = array->advisories[in.index];
      const metrics::AdvisoryRequest request = toRequest(a, array->step, array->rsu_id);
      const sim::VehicleRecord* vehicle = session_->find(a.vehicle_id);
      const metrics::AdvisoryVerdict verdict = metrics::validateAdvisory(
          request, step, toKnownVehicle(vehicle, lanes), limits, advised);
      if (!verdict.accepted) {
        reject(array->rsu_id, a.vehicle_id, static_cast<int>(verdict.reason), verdict.detail);
        continue;
      }
      try {
        session_->applyAdvisory(a.vehicle_id, a.action, a.accel_mps2);
      } catch (const std::exception& e) {
        // The validator and the road disagree (e.g. a lane that ends here) or SUMO refused
        // the command: reject it and keep the simulation running.
        reject(array->rsu_id, a.vehicle_id, palcas_msgs::AdvisoryRejection::NO_SUCH_LANE, e.what());
        continue;
      }
      advised.insert(a.vehicle_id);
      holds_.advised(a.vehicle_id, array->rsu_id, step, a.action);
      measure_->metrics().addAdvisoriesApplied();
    }
  }
  pending_.clear();
  for (const std::string& id :
       holds_.ending(step, late_this_step_, [this](const std::string& id) { return session_->find(id) != nullptr; }))
    session_->endCommand(id);
  late_this_step_.clear();
  const std::uint64_t k = session_->stepCount();
  if (k % static_cast<std::uint64_t>(options_.markers_every_steps) == 0 &&
      markers_pub_.getNumSubscribers() > 0) {
    // Every advisory in force, not only this step's: RSUs decide once a second, the markers
    // go out every few steps, and an arrow should stay while its command holds.
    markers_pub_.publish(markers_->dynamicMarkers(ros::Time(session_->timeS()),
                                                  session_->vehicles(), holds_.inForce()));
  }
}

void BridgeNode::setUpDiagnostics() {
  diagnostics_.setHardwareID("palcas_sumo_bridge");
  diagnostics_.add("lockstep", this, &BridgeNode::diagnoseLockstep);
  diagnostics_.add("simulation", this, &BridgeNode::diagnoseSimulation);
  diagnostics_.add("advice guard", this, &BridgeNode::diagnoseGuard);
}

void BridgeNode::diagnoseLockstep(diagnostic_updater::DiagnosticStatusWrapper& s) {
  LockstepFacts f;
  f.expected = options_.expected_rsus;
  f.lost = lockstep_->lostRsus();
  f.late_steps = lockstep_->lateSteps();
  f.late_steps_new = f.late_steps >= late_steps_reported_ ? f.late_steps - late_steps_reported_ : f.late_steps;
  late_steps_reported_ = f.late_steps;
  f.late_by_rsu = late_by_rsu_;
  f.decisions = decision_ms_.size();
  constexpr std::size_t RECENT = 2000;  // decisions: about the last 10 simulated minutes of 3 RSUs
  f.decision_p50_ms = recentPercentile(decision_ms_, RECENT, 50.0);
  f.decision_p99_ms = recentPercentile(decision_ms_, RECENT, 99.0);
  describeLockstep(f, s);
}

void BridgeNode::diagnoseSimulation(diagnostic_updater::DiagnosticStatusWrapper& s) {
  const metrics::EpisodeMetrics m = measure_->metrics().snapshot();
  SimulationFacts f;
  f.episode = episode_ + 1;
  f.episodes = options_.first_episode + options_.episodes;
  f.sim_s = session_->timeS();
  f.duration_s = options_.scenario.duration_s;
  const double wall_s = wallSeconds();
  f.real_time_factor = wall_s > 0.0 ? f.sim_s / wall_s : 0.0;
  f.on_road = m.vehicles_on_road;
  f.speed_mps = m.efficiency_all_mps;
  f.cr_pct = m.collision_rate_pct;
  f.dsr_pct = m.dsr_pct;
  f.msr_pct = m.msr_pct;
  f.collisions = m.collisions;
  f.teleports = m.teleports;
  f.vanished_vehicles = session_->vanishedVehicles();
  f.route_changes_failed = session_->routeChangesFailed();
  f.insertion_dropped = session_->insertionDropped();
  describeSimulation(f, s);
}

void BridgeNode::diagnoseGuard(diagnostic_updater::DiagnosticStatusWrapper& s) {
  const sim::SessionOptions& o = options_.session;
  const sim::GuardCounters& g = session_->guardCounters();
  GuardFacts f;
  f.advisory_control = o.advisory_control;
  f.busy_zones_on = o.guard_busy_speed_share > 0.0;
  f.zones = static_cast<int>(session_->road().clusters().size());
  for (int k = 0; k < f.zones; ++k)
    if (session_->zoneBusy(k)) f.busy_zones.push_back(k);
  for (const sim::VehicleRecord& v : session_->vehicles()) f.handed_back_now += v.handed_back ? 1 : 0;
  f.handbacks = g.handbacks;
  f.advice_dropped = g.handback_advice_dropped;
  f.lane_changes_busy_refused = g.lane_changes_busy_refused;
  f.accelerate_guarded_pct = g.accelerate_steps > 0
      ? 100.0 * static_cast<double>(g.accelerate_floored_steps + g.accelerate_released_steps) / g.accelerate_steps
      : 0.0;
  describeGuard(f, s);
}

void BridgeNode::publishMetrics() {
  palcas_msgs::EpisodeMetrics msg = toMsg(measure_->metrics().snapshot(), wallSeconds());
  msg.header.stamp = ros::Time(session_->timeS());
  msg.step = session_->stepCount();
  msg.insertion_dropped = static_cast<std::uint32_t>(session_->insertionDropped());
  metrics_pub_.publish(msg);
  // Time left over every remaining episode, at this episode's pace.
  const int episodes_left = options_.first_episode + options_.episodes - episode_;
  const double remaining_sim_s = options_.scenario.duration_s * episodes_left - msg.sim_seconds;
  const double left_s = msg.real_time_factor > 0.0 ? remaining_sim_s / msg.real_time_factor : 0.0;
  ROS_INFO("palcas bridge: episode %d/%d  t=%6.0f/%.0f s  on road %4u  speed %5.2f m/s (CAV %5.2f)  CR %5.2f%%  "
           "DSR %5.1f%%  MSR %5.1f%%  RTF %5.1fx  ~%.0f s left",
           episode_ + 1, options_.first_episode + options_.episodes, msg.sim_seconds, options_.scenario.duration_s, msg.vehicles_on_road, msg.efficiency_all_mps,
           msg.efficiency_cav_mps, msg.collision_rate_pct, msg.dsr_pct, msg.msr_pct,
           msg.real_time_factor, left_s);
}

void BridgeNode::startEpisode(int episode) {
  episode_ = episode;
  session_.reset();  // closes SUMO before the next one loads (one libsumo per process)
  session_ = std::make_unique<sim::SumoSession>(sessionOptionsFor(options_, sumocfg_path_, episode));
  measure_ = std::make_unique<EpisodeMeasure>(rules_);
  holds_.clear();
  pending_.clear();
  downlink_.clear();
  downlink_counts_ = v2x::DownlinkCounts{};
  late_by_rsu_.clear();
  decision_ms_.clear();
}

void BridgeNode::runEpisode(int episode) {
  wall_start_ = std::chrono::steady_clock::now();
  next_metrics_s_ = options_.metrics_period_s;
  const double duration_s = options_.scenario.duration_s;
  StepTimer timer;
  recorder_.reset();
  if (options_.trajectory_period_steps > 0) {
    recorder_ = std::make_unique<sim::RunRecorder>(episodeDir(options_, episode), options_.trajectory_period_steps);
  }
  publishStep();
  while (ros::ok() && session_->timeS() < duration_s - 1e-9) {
    const auto t_wait = std::chrono::steady_clock::now();
    if (lockstep_->enabled()) waitForAdvisories();
    applyAdvisories();
    const auto t0 = std::chrono::steady_clock::now();
    session_->step();
    const auto t1 = std::chrono::steady_clock::now();
    publishStep();
    diagnostics_.update();  // at most once per ~diagnostic_period (1 s of simulated time)
    if (recorder_) recorder_->addStep(session_->stepCount(), session_->timeS(), session_->vehicles());
    const auto t2 = std::chrono::steady_clock::now();
    timer.add(session_->vehicles().size(), std::chrono::duration<double>(t1 - t0).count(),
              std::chrono::duration<double>(t2 - t1).count(),
              std::chrono::duration<double>(t0 - t_wait).count());
    if (session_->timeS() >= next_metrics_s_ - 1e-9) {
      publishMetrics();
      next_metrics_s_ += options_.metrics_period_s;
    }
    if (options_.real_time_factor > 0.0) {
      const double due_s = session_->timeS() / options_.real_time_factor;
      const double ahead_s = due_s - wallSeconds();
      if (ahead_s > 0.0) std::this_thread::sleep_for(std::chrono::duration<double>(ahead_s));
    }
  }
  if (std::abs(session_->timeS() - (next_metrics_s_ - options_.metrics_period_s)) > 1e-9)
    publishMetrics();  // the final state, unless the periodic report just covered it
  if (recorder_) recorder_->close();
  RunSummary summary;
  summary.episode = episode;
  summary.metrics = measure_->metrics().snapshot();
  summary.wall_seconds = wallSeconds();
  summary.steps = session_->stepCount();
  summary.late_by_rsu = late_by_rsu_;
  for (int r = 0; r < metrics::REJECTION_REASON_COUNT; ++r)
    summary.rejections_by_reason[metrics::rejectionReasonName(static_cast<metrics::RejectionReason>(r))] =
        measure_->metrics().rejections(static_cast<metrics::RejectionReason>(r));
  summary.timing = timer;
  summary.decision_ms = decision_ms_;
  summary.lane_changes_done = session_->laneChangesDone();
  summary.lane_changes_dropped = session_->laneChangesDropped();
  summary.vanished_vehicles = session_->vanishedVehicles();
  summary.route_changes_failed = session_->routeChangesFailed();
  summary.guard = session_->guardCounters();
  summary.insertion_dropped = session_->insertionDropped();
  summary.downlink = downlink_counts_;
  writeMetricsJson(options_, summary, episode);
  ROS_INFO("palcas bridge: episode %d/%d done: %.0f s simulated in %.1f s; results in %s", episode + 1,
           options_.first_episode + options_.episodes, session_->timeS(), summary.wall_seconds, options_.out_dir.c_str());
}

int BridgeNode::run() {
  waitForPeers();
  const int first = options_.first_episode;
  episode_ = first;
  if (first > 0) startEpisode(first);  // a resumed training: seed + first, as numbered
  for (int episode = first; episode < first + options_.episodes && ros::ok(); ++episode) {
    if (episode > first) startEpisode(episode);
    runEpisode(episode);
  }
  // Stay up a moment: recorders and RSUs still have the last messages in flight.
  const auto linger_end = std::chrono::steady_clock::now() + std::chrono::duration<double>(options_.linger_s);
  while (ros::ok() && std::chrono::steady_clock::now() < linger_end)
    ros::getGlobalCallbackQueue()->callAvailable(ros::WallDuration(0.05));
  return 0;
}

}  // namespace palcas::bridge
