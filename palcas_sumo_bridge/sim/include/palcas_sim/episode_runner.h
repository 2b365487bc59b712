#pragma once
// The simulation driver of the bridge, without ROS: one episode is a loop of
//   publish step k -> wait (lockstep) for the RSUs' answers to k -> deliver them (V2X
//   channel) -> check each advisory -> actuate -> end expired commands -> SUMO step k+1
// with pacing, timing and recording. The transport (ROS topics in the bridge node, a script
// in tests) is an EpisodePort; answers enter through EpisodeRunner::onAnswer.

#include <palcas_core/metrics/advisory_validator.h>
#include <palcas_core/v2x/v2x_channel.h>

#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <unordered_set>
#include <vector>

#include "palcas_sim/advisory_holds.h"
#include "palcas_sim/lockstep.h"
#include "palcas_sim/run_recorder.h"
#include "palcas_sim/sumo_session.h"

namespace palcas::sim {

/// One RSU's answer to a step as the bridge received it (palcas_msgs/AdvisoryArray, checked
/// for authenticity by the transport).
struct AdviceArray {
  std::string rsu_id;
  std::uint64_t step = 0;   ///< the step whose state it answers
  float decision_ms = 0.0f; ///< the RSU's decision time [ms]
  std::vector<metrics::AdvisoryRequest> advisories;  ///< answers_step and rsu_id filled
};
using AdviceArrayPtr = std::shared_ptr<const AdviceArray>;

/// Cost per step against the number of vehicles on the road, in buckets of 50 vehicles:
/// SUMO's own step (with reading the subscriptions), the bridge's work around it
/// (conversion, publishing, measuring) and the lockstep (waiting for the RSUs' answers and
/// applying them).
class StepTimer {
 public:
  void add(std::size_t vehicles, double sumo_s, double bridge_s, double lockstep_s);
  struct Bucket {
    std::uint64_t steps = 0;
    double sumo_s = 0.0;
    double bridge_s = 0.0;
    double lockstep_s = 0.0;
  };
  const std::map<std::size_t, Bucket>& buckets() const { return buckets_; }
  static constexpr std::size_t BUCKET_WIDTH = 50;

 private:
  std::map<std::size_t, Bucket> buckets_;  ///< key = first vehicle count of the bucket
};

/// What the runner needs from its transport.
class EpisodePort {
 public:
  virtual ~EpisodePort() = default;
  /// false ends the episode after the current step (ROS shut down).
  virtual bool running() const = 0;
  /// The session's current step goes out (clock, events, vehicle states, tf) and is measured.
  virtual void publishStep(const SumoSession& session) = 0;
  /// Lets answers that arrived through (EpisodeRunner::onAnswer) at least once, then until
  /// `done()` or `deadline`.
  virtual void receive(std::chrono::steady_clock::time_point deadline, const std::function<bool()>& done) = 0;
  /// The lockstep closed a step with RSUs that missed it (`late`, non-empty) or that are now
  /// lost (`newly_lost`): for the metrics and the log.
  virtual void lockstepMissed(std::uint64_t step, const std::vector<std::string>& late,
                              const std::vector<std::string>& newly_lost) = 0;
  /// An advisory refused, with the rule it broke (counted, published and logged).
  virtual void rejected(const std::string& rsu_id, const std::string& vehicle_id,
                        metrics::RejectionReason reason, const std::string& detail) = 0;
  /// An advisory carried out.
  virtual void applied(const std::string& vehicle_id) = 0;
  /// After each step's actuation: the commands in force (rviz arrows).
  virtual void actuated(const SumoSession& session, const AdvisoryHolds& holds) = 0;
  /// After each SUMO step and its publication (diagnostics).
  virtual void stepped(const SumoSession& session) = 0;
  /// Every metrics_period_s of simulated time and once at the end (progress line, metrics topic).
  virtual void progress(const SumoSession& session) = 0;
};

struct RunnerOptions {
  double duration_s = 3600.0;          ///< simulated time per episode [s]
  std::vector<std::string> expected_rsus;  ///< empty: no lockstep (free-running)
  int lost_after_missed_steps = 50;    ///< Lockstep's
  double lockstep_deadline_s = 0.2;    ///< wall time an RSU has to answer a step [s]
  std::uint64_t max_advisory_age_steps = 0;  ///< the validator's max_step_age
  std::uint64_t advisory_hold_steps = 10;    ///< how long a command holds without a new one
  double real_time_factor = 0.0;       ///< > 0: no faster than this × real time; 0: as fast as possible
  double metrics_period_s = 60.0;      ///< simulated time between progress reports [s]
  v2x::ChannelParams v2x;              ///< off by default
  double step_length_s = 0.1;          ///< the channel's step [s]
  int trajectory_period_steps = 0;     ///< > 0: RunRecorder every that many steps
  /// Episode k's own folder (the recorder's files).
  std::function<std::string(int)> episode_dir;
};

/// What one episode's loop measured besides the metrics (the port measures those).
struct EpisodeRun {
  std::uint64_t steps = 0;
  double wall_s = 0.0;
  std::map<std::string, std::uint64_t> late_by_rsu;
  StepTimer timing;
  std::vector<float> decision_ms;  ///< decision latencies of answers that advised [ms]
  v2x::DownlinkCounts downlink;
};

class EpisodeRunner {
 public:
  /// Makes episode k's SUMO session (seed + k); called with 0 here.
  using SessionFactory = std::function<std::unique_ptr<SumoSession>(int episode)>;
  /// @throws std::invalid_argument for bad options (naming them) or whatever the factory throws.
  EpisodeRunner(RunnerOptions options, SessionFactory make_session);

  /// Closes the current SUMO (one libsumo per process) and loads episode k's; every
  /// per-episode state is reset.
  void startEpisode(int episode);
  /// Runs the current episode to duration_s or until the port stops running:
  /// beginEpisode(), advance() while it returns true, finishEpisode().
  EpisodeRun runEpisode(int episode, EpisodePort& port);
  /// The same loop a step at a time, for a caller that must return between steps (the
  /// Python module palcas_env hands each decision step to its caller):
  /// beginEpisode publishes the episode's first step;
  void beginEpisode(int episode, EpisodePort& port);
  /// advance runs one step (wait for answers, actuate, SUMO step, publish the next step) and
  /// returns whether the episode goes on (false: duration reached or the port stopped; then
  /// call finishEpisode, nothing else);
  bool advance(EpisodePort& port);
  /// finishEpisode closes the recording and returns what the loop measured.
  EpisodeRun finishEpisode(EpisodePort& port);

  enum class Verdict { kQueued, kUnknownRsu, kDuplicate };
  struct AnswerOutcome {
    Verdict verdict = Verdict::kQueued;
    bool late = false;                 ///< queued after its step closed (the validator decides)
    std::vector<std::string> revived;  ///< lost RSUs this answer brought back
  };
  /// An answer arrived (authentic): queued for the next actuation unless the lockstep
  /// refuses it. Free-running (no expected RSUs), every answer is queued.
  AnswerOutcome onAnswer(AdviceArrayPtr array);

  SumoSession& session() { return *session_; }
  const SumoSession& session() const { return *session_; }
  Lockstep& lockstep() { return lockstep_; }
  const Lockstep& lockstep() const { return lockstep_; }
  const AdvisoryHolds& holds() const { return holds_; }
  /// This episode's counts so far (diagnostics).
  const std::map<std::string, std::uint64_t>& lateByRsu() const { return run_.late_by_rsu; }
  const std::vector<float>& decisionMs() const { return run_.decision_ms; }
  double wallSeconds() const;
  /// Where RSU `rsu_id` ("rsu_<k>") stands along the road: its zone's centre [m]; NaN for
  /// one without a zone (the centralized baseline): no radio range applies to it.
  double rsuPositionM(const std::string& rsu_id) const;

 private:
  struct AdviceInFlight {
    AdviceArrayPtr array;
    std::size_t index = 0;
  };
  void publishStep(EpisodePort& port);
  void waitForAnswers(EpisodePort& port);
  void actuate(EpisodePort& port);
  /// The advisories that reach their CAVs this step: every queued one with the channel off;
  /// through latency, loss, range and max age with it on (counted in run_.downlink).
  std::vector<AdviceInFlight> deliver(std::uint64_t step);

  RunnerOptions options_;
  SessionFactory make_session_;
  std::unique_ptr<SumoSession> session_;
  Lockstep lockstep_;
  v2x::Channel channel_;  ///< before holds_: the hold length reads its keep_advice_s
  AdvisoryHolds holds_;
  v2x::DelayLine<AdviceInFlight> downlink_;
  std::vector<AdviceArrayPtr> pending_;  ///< answers for the open step, in arrival order
  std::unordered_set<std::string> late_this_step_;
  std::unique_ptr<RunRecorder> recorder_;
  EpisodeRun run_;
  double next_progress_s_ = 0.0;  ///< simulated time of the next progress report [s]
  std::chrono::steady_clock::time_point wall_start_ = std::chrono::steady_clock::now();
};

}  // namespace palcas::sim
