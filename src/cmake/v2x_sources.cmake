# v2x sources (lib/v2x/): the V2X channel (latency, loss, RSU range per message class) between the
# vehicles and the RSUs and between RSUs; the nodes wire it (README "V2X channel").
list(APPEND PALCAS_CORE_SOURCES
  lib/v2x/v2x_channel.cpp)
