# rsu sources: one RSU's controller (membership, decisions, learning, federation
# bookkeeping) and its cluster statistics
list(APPEND PALCAS_CORE_SOURCES
  lib/cluster_stats.cpp
  lib/rsu_controller.cpp
  lib/rsu_controller_io.cpp
)
