# federation sources (lib/federation/): both sides of a federation round, ROS-free: the
# server's round logic and checkpoints (palcas_fedserver wraps it) and the RSU's client
# (rounds, submissions, heartbeats, reconnects; palcas_rsu wraps it)
list(APPEND PALCAS_CORE_SOURCES
  lib/federation/federation_server.cpp
  lib/federation/federation_checkpoint.cpp
  lib/federation/federation_json.cpp
  lib/federation/federation_client.cpp
)
