# federation tests (test/federation/): rounds, rejections, liveness, checkpoints of
# FederationServer; FederationClient against an in-process server
palcas_core_add_gtest(federation_server_test test/federation/federation_server_test.cpp)
# The state files committed with the shipped policies must keep loading.
target_compile_definitions(federation_server_test PRIVATE
  PALCAS_POLICIES_DIR="${CMAKE_CURRENT_SOURCE_DIR}/../policies")
palcas_core_add_gtest(federation_client_test test/federation/federation_client_test.cpp)
