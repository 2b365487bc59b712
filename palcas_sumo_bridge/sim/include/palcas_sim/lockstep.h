#pragma once
// Lockstep bookkeeping between the bridge and its RSUs, without ROS: who is expected, who
// registered, who has answered the current step, who is late or lost. The bridge node
// asks complete() while it waits, up to its deadline.

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace palcas::sim {

class Lockstep {
 public:
  /// @param expected_rsus RSU ids the bridge waits for (empty = no lockstep).
  /// @param lost_after_missed_steps consecutive missed deadlines after which an RSU is
  ///        considered lost and no longer waited for (it is live again when it answers).
  /// @throws std::invalid_argument on duplicate or empty ids, or lost_after < 1.
  Lockstep(std::vector<std::string> expected_rsus, int lost_after_missed_steps);

  /// Start handshake. @return false (with *reason) for an RSU that is not expected.
  /// An RSU with answer_period_steps N > 1 answers (and is waited for) only on steps that are
  /// multiples of N, its decision steps: between them the bridge steps without a round trip.
  bool registerRsu(const std::string& rsu_id, std::string* reason, std::uint32_t answer_period_steps = 1);
  bool allRegistered() const;
  std::vector<std::string> unregistered() const;

  /// Opens step `step`: from now on answers for it count, and the RSUs due on it (period
  /// dividing the step) are waited for.
  void beginStep(std::uint64_t step);
  enum class Answer { kAccepted, kUnknownRsu, kStale, kDuplicate };
  /// Records that `rsu_id` answered `step`. A lost RSU is live again when it answers the
  /// open step, or a step at most REVIVE_WINDOW_STEPS old: a lost RSU is not waited for, so
  /// its answers always come after its step closed (a network link that came back).
  Answer onAnswer(const std::string& rsu_id, std::uint64_t step);
  static constexpr std::uint64_t REVIVE_WINDOW_STEPS = 10;
  /// Lost RSUs revived by an answer since the last call (for the log), then cleared.
  std::vector<std::string> takeRevived();
  /// True when every live, registered RSU due on the open step has answered it.
  bool complete() const;
  /// Live RSUs due on the open step that have not answered it yet.
  std::vector<std::string> waitingFor() const;
  /// Closes the open step. @return the due RSUs that missed it (late). Updates lost status;
  /// *newly_lost receives the ones lost on this step.
  std::vector<std::string> endStep(std::vector<std::string>* newly_lost);

  bool enabled() const { return !rsus_.empty(); }
  /// Whether an RSU may decide on the open step (and so waits for that step's vehicle event
  /// array): free-running (no expected RSU), an expected RSU not registered yet (its period
  /// is unknown), or a registered one due on it.
  bool mayDecideOnOpenStep() const;
  bool isLive(const std::string& rsu_id) const;
  /// Registered RSUs currently considered lost.
  std::vector<std::string> lostRsus() const;
  std::uint64_t lateSteps() const { return late_steps_; }
  std::uint64_t lateAnswers(const std::string& rsu_id) const;

 private:
  struct RsuStatus {
    bool registered = false;
    bool answered = false;
    bool due = true;                   ///< expected to answer the open step
    std::uint32_t answer_period = 1;   ///< answers steps that are multiples of it
    bool lost = false;
    int consecutive_misses = 0;
    std::uint64_t late_answers = 0;
  };
  std::map<std::string, RsuStatus> rsus_;
  int lost_after_;
  std::vector<std::string> revived_;
  std::uint64_t open_step_ = 0;
  bool step_open_ = false;
  std::uint64_t late_steps_ = 0;
};

}  // namespace palcas::sim
