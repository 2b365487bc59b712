# scenario sources (road spec -> netconvert sources, network generation, demand writer, a
# minimal XML tag reader)
list(APPEND PALCAS_SIM_SOURCES
  lib/road_spec.cpp
  lib/scenario_xml.cpp
  lib/scenario_network.cpp
  lib/scenario_config.cpp
  lib/scenario_writer.cpp)
