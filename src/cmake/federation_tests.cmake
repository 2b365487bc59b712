# federation tests (test/federation/): rounds, rejections, liveness, checkpoints of
# FederationServer; FederationClient against an in-process server
palcas_core_add_gtest(federation_server_test test/federation/federation_server_test.cpp)
palcas_core_add_gtest(federation_client_test test/federation/federation_client_test.cpp)
