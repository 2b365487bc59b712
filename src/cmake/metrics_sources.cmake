# metrics sources: episode bookkeeping (events, outcome tracker, metrics, advisory gate)
list(APPEND PALCAS_CORE_SOURCES
  lib/vehicle_event.cpp
  lib/outcome_tracker.cpp
  lib/episode_metrics.cpp
  lib/advisory_validator.cpp)
