# rsu sources: one RSU's controller (membership, decisions, learning, federation
# bookkeeping) and its cluster statistics
list(APPEND PALCAS_CORE_SOURCES
  lib/cluster_stats.cpp
  lib/rsu_controller.cpp
  lib/rsu_controller_io.cpp
)
# the RSU's federation client (rounds, submissions, heartbeats, reconnects) and its
# per-episode learning log: what the node used to hold, now testable without ROS
list(APPEND PALCAS_CORE_SOURCES
  lib/federation_client.cpp
  lib/learning_log.cpp
)
