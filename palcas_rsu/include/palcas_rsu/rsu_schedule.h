#pragma once
// When the RSU node does its periodic work, apart from ROS (tested without a master): which
// bridge steps are decisions, whether the steps between feed the period's rewards, what
// follows a published decision and in which order (gradient steps inline or on the learner
// thread, the federation client's tick, the checkpoint), and the learner thread itself.
// RsuNode does what the schedule says; the order is the reason this is one object:
// federation and checkpoints see the model as the decision used it, so the learner thread
// starts last and is joined before the controller is used again.

#include <cstdint>
#include <functional>
#include <future>

namespace palcas::rsu {

struct RsuScheduleOptions {
  int decision_period_steps = 10;     ///< >= 1: a decision every this many bridge steps
  bool train = false;                 ///< eval: no learning, federation ticks or checkpoints
  bool reward_over_period = false;    ///< the steps between decisions feed the rewards
  bool learner_thread = true;         ///< gradient steps on a worker thread (else inline)
  int checkpoint_every_decisions = 0; ///< >= 0; 0 = only at shutdown
  bool checkpoint_dir_set = false;    ///< no directory: no checkpoints at all
  bool federation = false;            ///< a federation client runs beside the controller
};

/// What follows one published decision, in this order.
struct AfterDecision {
  bool learn_inline = false;     ///< learn() now (no learner thread), before the rest
  bool federation_tick = false;  ///< the federation client's onDecision(time)
  bool checkpoint = false;       ///< write the checkpoint
  bool learn_on_thread = false;  ///< last: learn() on the learner thread (startLearning)
};

class RsuSchedule {
 public:
  /// Throws std::invalid_argument naming decision_period_steps (< 1) or
  /// checkpoint_every_decisions (< 0).
  explicit RsuSchedule(const RsuScheduleOptions& options);
  /// Joins a learner still running (its exception, if any, is dropped: nothing can act on
  /// it any more).
  ~RsuSchedule();
  RsuSchedule(const RsuSchedule&) = delete;
  RsuSchedule& operator=(const RsuSchedule&) = delete;

  /// True at the bridge steps the RSU decides at (every decision_period_steps, from 0).
  bool decidesAt(uint64_t step) const;
  /// True when a step between decisions must reach the controller (observeStep): training
  /// with the reward over the decision's period.
  bool observesBetweenDecisions() const;

  /// Counts one published decision and says what follows it. Learning is inline without
  /// a learner thread (a no-op of the controller in eval, as always), on the thread only in
  /// training; the federation client ticks in training; the checkpoint is due in training
  /// with a directory, every checkpoint_every_decisions decisions.
  AfterDecision decided();
  /// Decisions counted by decided().
  uint64_t decisions() const { return decisions_; }

  /// Runs `learn` on the learner thread. Throws std::logic_error if one is still running
  /// (join it first: finishLearning()).
  void startLearning(std::function<void()> learn);
  /// Waits for the learner thread, if any, and rethrows what `learn` threw. Call before any
  /// other use of what `learn` touches, and at shutdown.
  void finishLearning();
  /// True while a started learner was not finished.
  bool learning() const { return learner_.valid(); }

 private:
  RsuScheduleOptions options_;
  uint64_t decisions_ = 0;
  std::future<void> learner_;
};

}  // namespace palcas::rsu
