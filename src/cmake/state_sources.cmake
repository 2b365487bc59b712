# state sources (lib/state/): neighbours, state layout and state builder.
list(APPEND PALCAS_CORE_SOURCES
  lib/state/neighbours.cpp
  lib/state/state_layout.cpp
  lib/state/state_builder.cpp)
