# rsu sources (lib/rsu/): one RSU's controller (membership, decisions, learning, federation
# bookkeeping), its open transitions and the rules that close them, its cluster statistics
# and its per-episode learning log: what the node used to hold, now testable without ROS
list(APPEND PALCAS_CORE_SOURCES
  lib/rsu/cluster_stats.cpp
  lib/rsu/rsu_controller.cpp
  lib/rsu/rsu_controller_io.cpp
  lib/rsu/rule_advisor.cpp
  lib/rsu/transition_book.cpp
  lib/rsu/learning_log.cpp
)
