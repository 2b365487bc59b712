# metrics sources (lib/metrics/): episode bookkeeping (events, outcome tracker, metrics,
# advisory gate)
list(APPEND PALCAS_CORE_SOURCES
  lib/metrics/vehicle_event.cpp
  lib/metrics/outcome_tracker.cpp
  lib/metrics/episode_metrics.cpp
  lib/metrics/advisory_validator.cpp)
