#pragma once
// Terminal rewards for tests: each amount different and exact in binary, so every expected
// reward is exact and shows which amount was applied.

#include "palcas_core/reward/terminal_rewards.h"

namespace palcas_test {

inline palcas::TerminalRewards exactTerminalRewards() {
  palcas::TerminalRewards t;
  t.collision_penalty = 10.0;
  t.exit_taken_bonus = 2.0;
  t.exit_missed_penalty = 8.0;
  t.exit_missed_terminal = true;
  t.merge_failed_penalty = 4.0;
  return t;
}

}  // namespace palcas_test
