list(APPEND PALCAS_SIM_SOURCES lib/road_layout.cpp lib/lockstep.cpp lib/run_recorder.cpp lib/advisory_holds.cpp lib/sumo_outputs.cpp
  lib/episode_runner_base.cpp lib/roadside.cpp)
