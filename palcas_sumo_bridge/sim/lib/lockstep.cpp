#include "palcas_sim/lockstep.h"

#include <stdexcept>

namespace palcas::sim {

Lockstep::Lockstep(std::vector<std::string> expected_rsus, int lost_after_missed_steps)
    : lost_after_(lost_after_missed_steps) {
  if (lost_after_ < 1)
    throw std::invalid_argument("Lockstep: lost_after_missed_steps must be >= 1, got " +
                                std::to_string(lost_after_));
  for (const std::string& id : expected_rsus) {
    if (id.empty()) throw std::invalid_argument("Lockstep: empty RSU id");
    if (!rsus_.emplace(id, RsuStatus{}).second)
      throw std::invalid_argument("Lockstep: RSU '" + id + "' listed twice");
  }
}

bool Lockstep::registerRsu(const std::string& rsu_id, std::string* reason,
                           std::uint32_t answer_period_steps) {
  auto it = rsus_.find(rsu_id);
  if (it == rsus_.end()) {
    if (reason) *reason = "RSU '" + rsu_id + "' is not in the bridge's expected_rsus";
    return false;
  }
  it->second.registered = true;
  it->second.lost = false;
  it->second.consecutive_misses = 0;
  it->second.answer_period = answer_period_steps > 1 ? answer_period_steps : 1;
  // Registered while a step is open: due on it only if it is one of its steps.
  it->second.due = !step_open_ || open_step_ % it->second.answer_period == 0;
  return true;
}

bool Lockstep::allRegistered() const {
  for (const auto& [id, s] : rsus_)
    if (!s.registered) return false;
  return true;
}

bool Lockstep::mayDecideOnOpenStep() const {
  if (rsus_.empty()) return true;
  for (const auto& [id, s] : rsus_)
    if (!s.registered || s.due) return true;
  return false;
}

std::vector<std::string> Lockstep::unregistered() const {
  std::vector<std::string> out;
  for (const auto& [id, s] : rsus_)
    if (!s.registered) out.push_back(id);
  return out;
}

void Lockstep::beginStep(std::uint64_t step) {
  open_step_ = step;
  step_open_ = true;
  for (auto& [id, s] : rsus_) {
    s.answered = false;
    s.due = step % s.answer_period == 0;
  }
}

Lockstep::Answer Lockstep::onAnswer(const std::string& rsu_id, std::uint64_t step) {
  auto it = rsus_.find(rsu_id);
  if (it == rsus_.end()) return Answer::kUnknownRsu;
  RsuStatus& s = it->second;
  if (!step_open_ || step != open_step_) {
    ++s.late_answers;
    if (s.lost && step <= open_step_ && open_step_ - step <= REVIVE_WINDOW_STEPS) {
      s.lost = false;  // waited for again from the next step on
      s.consecutive_misses = 0;
      revived_.push_back(rsu_id);
    }
    return Answer::kStale;
  }
  if (s.answered) return Answer::kDuplicate;
  s.answered = true;
  // An answer proves the RSU is there, even if it never registered or was lost.
  s.registered = true;
  if (s.lost) revived_.push_back(rsu_id);
  s.lost = false;
  s.consecutive_misses = 0;
  return Answer::kAccepted;
}

bool Lockstep::complete() const {
  for (const auto& [id, s] : rsus_)
    if (s.registered && s.due && !s.lost && !s.answered) return false;
  return true;
}

std::vector<std::string> Lockstep::waitingFor() const {
  std::vector<std::string> out;
  for (const auto& [id, s] : rsus_)
    if (s.registered && s.due && !s.lost && !s.answered) out.push_back(id);
  return out;
}

std::vector<std::string> Lockstep::endStep(std::vector<std::string>* newly_lost) {
  std::vector<std::string> late;
  for (auto& [id, s] : rsus_) {
    if (!s.registered || !s.due || s.lost || s.answered) continue;
    late.push_back(id);
    if (++s.consecutive_misses >= lost_after_) {
      s.lost = true;
      if (newly_lost) newly_lost->push_back(id);
    }
  }
  if (!late.empty()) ++late_steps_;
  step_open_ = false;
  return late;
}

std::vector<std::string> Lockstep::takeRevived() {
  std::vector<std::string> out;
  out.swap(revived_);
  return out;
}

bool Lockstep::isLive(const std::string& rsu_id) const {
  auto it = rsus_.find(rsu_id);
  return it != rsus_.end() && it->second.registered && !it->second.lost;
}

std::vector<std::string> Lockstep::lostRsus() const {
  std::vector<std::string> out;
  for (const auto& [id, s] : rsus_)
    if (s.registered && s.lost) out.push_back(id);
  return out;
}

std::uint64_t Lockstep::lateAnswers(const std::string& rsu_id) const {
  auto it = rsus_.find(rsu_id);
  return it == rsus_.end() ? 0 : it->second.late_answers;
}

}  // namespace palcas::sim
