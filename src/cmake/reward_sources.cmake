# reward sources (lib/reward/): RSS, the reward, its parameters, the CAV's situation.
list(APPEND PALCAS_CORE_SOURCES
  lib/reward/rss.cpp
  lib/reward/reward.cpp
  lib/reward/reward_params.cpp
  lib/reward/cav_situation.cpp)
