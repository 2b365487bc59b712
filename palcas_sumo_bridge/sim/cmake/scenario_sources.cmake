# scenario sources (road spec -> netconvert sources, network generation, demand writer, a
# minimal XML tag reader, a user's own road found in its network)
list(APPEND PALCAS_SIM_SOURCES
  lib/road_spec.cpp
  lib/scenario_xml.cpp
  lib/scenario_network.cpp
  lib/scenario_config.cpp
  lib/scenario_writer.cpp
  lib/own_road.cpp)
