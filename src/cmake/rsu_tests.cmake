# rsu tests: one gtest per module
palcas_core_add_gtest(cluster_stats_test test/cluster_stats_test.cpp)
palcas_core_add_gtest(rsu_controller_test test/rsu_controller_test.cpp)
palcas_core_add_gtest(federation_client_test test/federation_client_test.cpp)
palcas_core_add_gtest(learning_log_test test/learning_log_test.cpp)
