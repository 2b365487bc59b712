#include "palcas_sim/episode_runner.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <thread>

#include "palcas_core/common/action.h"

namespace palcas::sim {
namespace {

/// The rejection reason that reports a guard's verdict other than kCarryOut.
metrics::RejectionReason guardRejection(AdviceVerdict verdict) {
  switch (verdict) {
    case AdviceVerdict::kDropHandedBack: return metrics::RejectionReason::kGuardHandedBack;
    case AdviceVerdict::kRefuseInsertionEdge: return metrics::RejectionReason::kGuardInsertionEdge;
    case AdviceVerdict::kRefuseCooldown: return metrics::RejectionReason::kGuardCooldown;
    case AdviceVerdict::kRefuseBusy: return metrics::RejectionReason::kGuardBusyZone;
    case AdviceVerdict::kCarryOut: break;
  }
  throw std::logic_error("guardRejection: a carried-out advisory is not a rejection");
}

std::string guardRefusalDetail(AdviceVerdict verdict, const metrics::AdvisoryRequest& a) {
  const std::string action = actionName(static_cast<Action>(a.action_code));
  switch (verdict) {
    case AdviceVerdict::kDropHandedBack: return action + " dropped: its zone is busy and it drives itself";
    case AdviceVerdict::kRefuseInsertionEdge: return action + " refused on the edge where SUMO inserts traffic";
    case AdviceVerdict::kRefuseCooldown: return action + " refused within the cooldown after its last advised change";
    case AdviceVerdict::kRefuseBusy: return action + " refused in a busy zone";
    case AdviceVerdict::kCarryOut: break;
  }
  return action;
}

using Clock = std::chrono::steady_clock;

double secondsBetween(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

const RunnerOptions& checked(const RunnerOptions& o) {
  auto require = [](bool ok, const std::string& what) {
    if (!ok) throw std::invalid_argument("EpisodeRunner: " + what);
  };
  require(std::isfinite(o.duration_s) && o.duration_s > 0.0, "duration_s must be > 0");
  require(std::isfinite(o.lockstep_deadline_s) && o.lockstep_deadline_s >= 0.0,
          "lockstep_deadline_s must be >= 0");
  require(std::isfinite(o.real_time_factor) && o.real_time_factor >= 0.0, "real_time_factor must be >= 0");
  require(std::isfinite(o.metrics_period_s) && o.metrics_period_s > 0.0, "metrics_period_s must be > 0");
  require(o.trajectory_period_steps >= 0, "trajectory_period_steps must be >= 0");
  require(o.trajectory_period_steps == 0 || static_cast<bool>(o.episode_dir),
          "trajectory_period_steps > 0 needs episode_dir");
  return o;
}

}  // namespace

EpisodeRunner::EpisodeRunner(RunnerOptions options, SessionFactory make_session)
    : options_(checked(options)), make_session_(std::move(make_session)),
      lockstep_(options_.expected_rsus, options_.lost_after_missed_steps),
      channel_(options_.v2x, options_.step_length_s),
      // Over an impaired channel a CAV keeps its last advisory past the hold until a newer one
      // gets through (v2x keep_advice_s): a lost one then leaves the pace it was given, not
      // its own car following. Every decision re-advises a zone's CAVs, so with nothing lost
      // a newer advisory replaces the held one at the usual step.
      holds_(options_.advisory_hold_steps, channel_.keepAdviceSteps()) {
  if (!make_session_) throw std::invalid_argument("EpisodeRunner: no session factory");
  session_ = make_session_(0);
}

void EpisodeRunner::startEpisode(int episode) {
  session_.reset();  // closes SUMO before the next one loads (one libsumo per process)
  session_ = make_session_(episode);
  holds_.clear();
  pending_.clear();
  downlink_.clear();
  late_this_step_.clear();
  run_ = EpisodeRun{};
}

double EpisodeRunner::wallSeconds() const { return secondsBetween(wall_start_, Clock::now()); }

EpisodeRunner::AnswerOutcome EpisodeRunner::onAnswer(AdviceArrayPtr array) {
  AnswerOutcome out;
  if (!lockstep_.enabled()) {
    pending_.push_back(std::move(array));  // free-running: every publisher may advise
    return out;
  }
  const Lockstep::Answer answer = lockstep_.onAnswer(array->rsu_id, array->step);
  out.revived = lockstep_.takeRevived();
  switch (answer) {
    case Lockstep::Answer::kAccepted:
      pending_.push_back(std::move(array));
      break;
    case Lockstep::Answer::kStale:
      // Too late for the lockstep, but the validator decides whether its age is acceptable.
      out.late = true;
      pending_.push_back(std::move(array));
      break;
    case Lockstep::Answer::kDuplicate:
      out.verdict = Verdict::kDuplicate;
      break;
    case Lockstep::Answer::kUnknownRsu:
      out.verdict = Verdict::kUnknownRsu;
      break;
  }
  return out;
}

double EpisodeRunner::rsuPositionM(const std::string& rsu_id) const {
  const auto& clusters = session_->road().clusters();
  if (rsu_id.rfind("rsu_", 0) != 0 || rsu_id.size() == 4 ||
      rsu_id.find_first_not_of("0123456789", 4) != std::string::npos)
    return std::numeric_limits<double>::quiet_NaN();
  const std::size_t k = std::stoul(rsu_id.substr(4));
  if (k >= clusters.size()) return std::numeric_limits<double>::quiet_NaN();
  return 0.5 * (clusters[k].x_start_m + clusters[k].x_end_m);
}

void EpisodeRunner::publishStep(EpisodePort& port) {
  // Opened before the state goes out: an answer to it counts however fast it comes.
  lockstep_.beginStep(session_->stepCount());
  port.publishStep(*session_);
}

void EpisodeRunner::waitForAnswers(EpisodePort& port) {
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                           std::chrono::duration<double>(options_.lockstep_deadline_s));
  port.receive(deadline, [this] { return lockstep_.complete(); });
  std::vector<std::string> newly_lost;
  const std::vector<std::string> late = lockstep_.endStep(&newly_lost);
  late_this_step_ = std::unordered_set<std::string>(late.begin(), late.end());
  for (const std::string& id : lockstep_.lostRsus()) late_this_step_.insert(id);
  for (const std::string& id : late) ++run_.late_by_rsu[id];
  if (!late.empty() || !newly_lost.empty()) port.lockstepMissed(session_->stepCount(), late, newly_lost);
}

std::vector<EpisodeRunner::AdviceInFlight> EpisodeRunner::deliver(std::uint64_t step) {
  v2x::DownlinkCounts& counts = run_.downlink;
  std::vector<AdviceInFlight> arrived;
  for (const AdviceArrayPtr& array : pending_)
    for (std::size_t i = 0; i < array->advisories.size(); ++i) {
      ++counts.sent;
      if (!channel_.enabled()) {
        ++counts.delivered;
        arrived.push_back({array, i});
        continue;
      }
      const v2x::Delivery d = channel_.transmit(v2x::MessageClass::ADVISORY, array->rsu_id,
                                                array->advisories[i].vehicle_id, array->step);
      if (d.lost) ++counts.lost;
      else downlink_.push(array->step + d.delay_steps, {array, i});
    }
  if (!channel_.enabled()) return arrived;
  const std::uint64_t max_age = channel_.stepsWithin(channel_.params().max_advice_age_s);
  for (AdviceInFlight& in : downlink_.release(step)) {
    const std::uint64_t age = step >= in.array->step ? step - in.array->step : 0;
    if (age > max_age) {
      ++counts.too_old;
      continue;
    }
    // Range when it arrives: a CAV that drove out of its RSU's reach does not hear it.
    const VehicleRecord* vehicle = session_->find(in.array->advisories[in.index].vehicle_id);
    const double rsu_x = rsuPositionM(in.array->rsu_id);
    if (vehicle && !std::isnan(rsu_x) && !channel_.inRange(rsu_x, vehicle->x_m)) {
      ++counts.out_of_range;
      continue;
    }
    ++counts.delivered;
    if (age > 0) ++counts.late;
    counts.delivered_age_sum_s += static_cast<double>(age) * channel_.stepLengthS();
    arrived.push_back(std::move(in));
  }
  // Arrival order over a network differs between runs; two RSUs may advise one CAV at once
  // (stale states put it in both zones). The newest decision wins, then the lower RSU id: the
  // same every run (the others are rejected as duplicates).
  std::stable_sort(arrived.begin(), arrived.end(), [](const AdviceInFlight& a, const AdviceInFlight& b) {
    if (a.array->step != b.array->step) return a.array->step > b.array->step;
    if (a.array->rsu_id != b.array->rsu_id) return a.array->rsu_id < b.array->rsu_id;
    return a.index < b.index;
  });
  return arrived;
}

void EpisodeRunner::actuate(EpisodePort& port) {
  port.receive(Clock::now(), [] { return true; });  // free-running answers, late ones
  metrics::AdvisoryLimits limits;
  limits.max_step_age = options_.max_advisory_age_steps;
  // Advice the channel delayed answers an earlier step: as old as the channel allows.
  if (channel_.enabled())
    limits.max_step_age = std::max(limits.max_step_age, channel_.stepsWithin(channel_.params().max_advice_age_s));
  const std::uint64_t step = session_->stepCount();
  for (const AdviceArrayPtr& array : pending_)
    if (!array->advisories.empty()) {
      run_.decision_ms.push_back(array->decision_ms);
      if (recorder_)
        recorder_->addDecision(session_->timeS(), array->rsu_id, array->decision_ms, array->advisories.size());
    }
  std::unordered_set<std::string> advised;
  for (const AdviceInFlight& in : deliver(step)) {
    const metrics::AdvisoryRequest& a = in.array->advisories[in.index];
    const metrics::AdvisoryVerdict verdict =
        metrics::validateAdvisory(a, step, session_->known(a.vehicle_id), limits, advised);
    if (!verdict.accepted) {
      port.rejected(in.array->rsu_id, a.vehicle_id, verdict.reason, verdict.detail);
      continue;
    }
    AdviceVerdict carried;
    try {
      carried = session_->applyAdvisory(a.vehicle_id, a.action_code, a.accel_mps2);
    } catch (const std::exception& e) {
      // SUMO refused the command: reject it and keep the simulation running.
      port.rejected(in.array->rsu_id, a.vehicle_id, metrics::RejectionReason::kSumoRefused, e.what());
      continue;
    }
    advised.insert(a.vehicle_id);
    // A kept advisory is a guess at the one that was lost: with keep_slowing_advice off, a
    // slowing one is not guessed on.
    const bool slows = a.action_code == static_cast<int>(Action::kAccelerate) && a.accel_mps2 < 0.0;
    // A declined one holds too: what the guard made of it (its own lane, or its own driving)
    // stands until the hold ends, as a carried-out one would.
    holds_.advised(a.vehicle_id, in.array->rsu_id, step, a.action_code,
                   channel_.params().keep_slowing_advice || !slows);
    if (carried == AdviceVerdict::kCarryOut) port.applied(a.vehicle_id);
    else port.rejected(in.array->rsu_id, a.vehicle_id, guardRejection(carried), guardRefusalDetail(carried, a));
  }
  pending_.clear();
  for (const std::string& id :
       holds_.ending(step, late_this_step_, [this](const std::string& id) { return session_->find(id) != nullptr; }))
    session_->endCommand(id);
  late_this_step_.clear();
  port.actuated(*session_, holds_);
}

EpisodeRun EpisodeRunner::runEpisode(int episode, EpisodePort& port) {
  beginEpisode(episode, port);
  while (advance(port)) {
  }
  return finishEpisode(port);
}

void EpisodeRunner::beginEpisode(int episode, EpisodePort& port) {
  wall_start_ = Clock::now();
  next_progress_s_ = options_.metrics_period_s;
  recorder_.reset();
  if (options_.trajectory_period_steps > 0)
    recorder_ = std::make_unique<RunRecorder>(options_.episode_dir(episode), options_.trajectory_period_steps);
  publishStep(port);
}

bool EpisodeRunner::advance(EpisodePort& port) {
  if (!port.running() || session_->timeS() >= options_.duration_s - 1e-9) return false;
  const auto t_wait = Clock::now();
  if (lockstep_.enabled()) waitForAnswers(port);
  actuate(port);
  const auto t0 = Clock::now();
  session_->step();
  const auto t1 = Clock::now();
  publishStep(port);
  port.stepped(*session_);
  if (recorder_) recorder_->addStep(session_->stepCount(), session_->timeS(), session_->vehicles());
  const auto t2 = Clock::now();
  run_.timing.add(session_->vehicles().size(), secondsBetween(t0, t1), secondsBetween(t1, t2),
                  secondsBetween(t_wait, t0));
  if (session_->timeS() >= next_progress_s_ - 1e-9) {
    port.progress(*session_);
    next_progress_s_ += options_.metrics_period_s;
  }
  if (options_.real_time_factor > 0.0) {
    const double ahead_s = session_->timeS() / options_.real_time_factor - wallSeconds();
    if (ahead_s > 0.0) std::this_thread::sleep_for(std::chrono::duration<double>(ahead_s));
  }
  return port.running() && session_->timeS() < options_.duration_s - 1e-9;
}

EpisodeRun EpisodeRunner::finishEpisode(EpisodePort& port) {
  // The final state, unless the periodic report just covered it.
  if (std::abs(session_->timeS() - (next_progress_s_ - options_.metrics_period_s)) > 1e-9) port.progress(*session_);
  if (recorder_) recorder_->close();
  run_.steps = session_->stepCount();
  run_.wall_s = wallSeconds();
  return run_;
}

}  // namespace palcas::sim
