#include "palcas_rsu/rsu_schedule.h"

#include <stdexcept>
#include <string>
#include <utility>

namespace palcas::rsu {

namespace {

const RsuScheduleOptions& validated(const RsuScheduleOptions& o) {
  if (o.decision_period_steps < 1)
    throw std::invalid_argument("RsuSchedule: decision_period_steps = " +
                                std::to_string(o.decision_period_steps) + " must be >= 1");
  if (o.checkpoint_every_decisions < 0)
    throw std::invalid_argument("RsuSchedule: checkpoint_every_decisions = " +
                                std::to_string(o.checkpoint_every_decisions) + " must be >= 0");
  return o;
}

}  // namespace

RsuSchedule::RsuSchedule(const RsuScheduleOptions& options) : options_(validated(options)) {}

RsuSchedule::~RsuSchedule() {
  try {
    finishLearning();
  } catch (...) {  // a destructor must not throw; the node joins at shutdown and logs
  }
}

bool RsuSchedule::decidesAt(uint64_t step) const {
  return step % static_cast<uint64_t>(options_.decision_period_steps) == 0;
}

bool RsuSchedule::observesBetweenDecisions() const {
  return options_.train && options_.reward_over_period;
}

AfterDecision RsuSchedule::decided() {
  ++decisions_;
  AfterDecision after;
  after.learn_inline = !options_.learner_thread;
  after.federation_tick = options_.train && options_.federation;
  after.checkpoint = options_.train && options_.checkpoint_every_decisions > 0 &&
                     options_.checkpoint_dir_set &&
                     decisions_ % static_cast<uint64_t>(options_.checkpoint_every_decisions) == 0;
  after.learn_on_thread = options_.learner_thread && options_.train;
  return after;
}

void RsuSchedule::startLearning(std::function<void()> learn) {
  if (learner_.valid())
    throw std::logic_error("RsuSchedule::startLearning: the learner of the last decision still runs");
  learner_ = std::async(std::launch::async, std::move(learn));
}

void RsuSchedule::finishLearning() {
  if (learner_.valid()) learner_.get();  // rethrows what learn() threw; invalid afterwards
}

}  // namespace palcas::rsu
