# federation tests: rounds, rejections, liveness, checkpoints of FederationServer
palcas_core_add_gtest(federation_server_test test/federation_server_test.cpp)
# message authentication: HMAC-SHA256 vectors, tampering, key files
palcas_core_add_gtest(message_auth_test test/message_auth_test.cpp)
