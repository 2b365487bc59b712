# reward sources (lib/reward/): RSS, the reward, its parameters, the CAV's situation, the
# terminal rewards of a transition's outcome.
list(APPEND PALCAS_CORE_SOURCES
  lib/reward/rss.cpp
  lib/reward/reward.cpp
  lib/reward/reward_params.cpp
  lib/reward/cav_situation.cpp
  lib/reward/terminal_rewards.cpp)
