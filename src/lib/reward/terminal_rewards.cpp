// Terminal rewards: validation and the two ways a transition's reward is settled.
// The order of the additions is part of the behaviour (floating point): keep it.
#include "palcas_core/reward/terminal_rewards.h"

#include <cmath>

#include "palcas_core/common/checks.h"

namespace palcas {

namespace {

void requireAmount(double value, const char* field, const char* effect) {
  common::require(std::isfinite(value) && value >= 0.0, field, " = ", value,
                  " must be finite and >= 0 (it is ", effect, ")");
}

}  // namespace

void validateTerminalRewards(const TerminalRewards& t) {
  requireAmount(t.collision_penalty, "collision_penalty", "subtracted");
  requireAmount(t.exit_taken_bonus, "exit_taken_bonus", "added");
  requireAmount(t.exit_missed_penalty, "exit_missed_penalty", "subtracted");
  requireAmount(t.merge_failed_penalty, "merge_failed_penalty", "subtracted");
}

TransitionReward leftTheRoad(double reward_so_far, const TransitionOutcome& outcome,
                             const TerminalRewards& terminal) {
  common::require(std::isfinite(reward_so_far), "leftTheRoad: reward_so_far = ", reward_so_far,
                  " must be finite");
  TransitionReward r{reward_so_far, true};
  if (outcome.collided) r.reward -= terminal.collision_penalty;
  if (outcome.exit_taken) r.reward += terminal.exit_taken_bonus;
  if (outcome.merge_failed) r.reward -= terminal.merge_failed_penalty;
  return r;
}

TransitionReward stillOnTheRoad(double reward, bool done, const TransitionOutcome& outcome,
                                const TerminalRewards& terminal) {
  common::require(std::isfinite(reward), "stillOnTheRoad: reward = ", reward, " must be finite");
  TransitionReward r{reward, done};
  if (outcome.merge_failed) r.reward -= terminal.merge_failed_penalty;
  if (outcome.exit_missed) {
    r.reward -= terminal.exit_missed_penalty;
    if (terminal.exit_missed_terminal) r.done = true;
  }
  return r;
}

}  // namespace palcas
