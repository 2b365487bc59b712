# state_reward sources: road snapshot, neighbours, state layout/builder, RSS, reward.
list(APPEND PALCAS_CORE_SOURCES
  lib/road_snapshot.cpp
  lib/neighbours.cpp
  lib/state_layout.cpp
  lib/state_builder.cpp
  lib/rss.cpp
  lib/reward.cpp
  lib/reward_params.cpp
  lib/cav_situation.cpp)
