# rsu tests: one gtest per module
palcas_core_add_gtest(cluster_stats_test test/cluster_stats_test.cpp)
palcas_core_add_gtest(rsu_controller_test test/rsu_controller_test.cpp)
