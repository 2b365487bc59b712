# federation sources: the federation server's round logic (ROS-free; palcas_fedserver wraps it)
# and the HMAC tags that authenticate advisories and model submissions
list(APPEND PALCAS_CORE_SOURCES
  lib/federation_server.cpp
  lib/federation_checkpoint.cpp
  lib/federation_json.cpp
  lib/message_auth.cpp
)
