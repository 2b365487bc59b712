# federation tests: rounds, rejections, liveness, checkpoints of FederationServer
palcas_core_add_gtest(federation_server_test test/federation_server_test.cpp)
