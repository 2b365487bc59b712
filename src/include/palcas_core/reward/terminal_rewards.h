#pragma once
// The rewards of the outcomes that end or fail a CAV's task: a collision, its exit taken or
// missed, a failed merge. The paper defines none (every one 0 / false by default); why they
// exist and the values shipped: src/doc/rsu.md ("Closing a pending transition", "Choices").
// Pure functions of a transition's reward: the RSU decides which outcome happened
// (rsu/transition_book.h), these say what it is worth.

namespace palcas {

/// The terminal rewards (config/rsu.yaml, rsu/<field>; shipped in config/departures.yaml).
/// Each number is finite and >= 0: the sign of its effect is fixed by its name.
struct TerminalRewards {
  /// Subtracted from the last reward of a CAV removed by a COLLISION or TELEPORT event.
  double collision_penalty = 0.0;
  /// Added to the transition that ends on the CAV's own off-ramp (exit taken; terminal).
  double exit_taken_bonus = 0.0;
  /// Subtracted from the transition in which a CAV passed its off-ramp without taking it.
  double exit_missed_penalty = 0.0;
  /// true: that transition is terminal (the task of reaching the exit ended, failed); the
  /// CAV's later decisions are new episodes of a through vehicle. false: it goes on.
  bool exit_missed_terminal = false;
  /// Subtracted from the transition in which a merging CAV failed (MERGE_FAILED event).
  double merge_failed_penalty = 0.0;
};

/// Throws std::invalid_argument naming the first bad field and its value
/// ("collision_penalty = -1 must be finite and >= 0 (it is subtracted)").
void validateTerminalRewards(const TerminalRewards& terminal);

/// What happened to a CAV while its decision held, as far as the terminal rewards care.
struct TransitionOutcome {
  bool collided = false;      ///< COLLISION or TELEPORT event
  bool exit_taken = false;    ///< EXIT_OK event, or the CAV seen on its off-ramp
  bool exit_missed = false;   ///< passed its off-ramp on the mainline (event or road)
  bool merge_failed = false;  ///< MERGE_FAILED event
};

/// The reward and done flag a transition is stored with.
struct TransitionReward {
  double reward = 0.0;
  bool done = false;
};

/// A CAV that left the road (removed by an event, vanished, or on its off-ramp): always
/// terminal. `reward_so_far`: its reward since the decision; then, in this order, minus
/// collision_penalty if collided, plus exit_taken_bonus if the exit was taken, minus
/// merge_failed_penalty if its merge failed (exit_missed does not apply off the road).
/// Throws std::invalid_argument naming `reward_so_far` when it is not finite.
TransitionReward leftTheRoad(double reward_so_far, const TransitionOutcome& outcome,
                             const TerminalRewards& terminal);

/// A CAV still on the road: `reward` (its period reward now) minus merge_failed_penalty if
/// its merge failed, then minus exit_missed_penalty if it passed its exit, which also ends
/// the transition when exit_missed_terminal; `done` as its place on the road says otherwise.
/// Throws std::invalid_argument naming `reward` when it is not finite.
TransitionReward stillOnTheRoad(double reward, bool done, const TransitionOutcome& outcome,
                                const TerminalRewards& terminal);

}  // namespace palcas
