# rsu tests (test/rsu/): one gtest per module
palcas_core_add_gtest(cluster_stats_test test/rsu/cluster_stats_test.cpp)
palcas_core_add_gtest(rsu_controller_test test/rsu/rsu_controller_test.cpp)
palcas_core_add_gtest(rule_advisor_test test/rsu/rule_advisor_test.cpp)
palcas_core_add_gtest(transition_book_test test/rsu/transition_book_test.cpp)
palcas_core_add_gtest(learning_log_test test/rsu/learning_log_test.cpp)
# The refactoring guard of the RSU split (issue 20 item 3): fingerprints of a scripted
# training run, recorded before the split.
palcas_core_add_gtest(rsu_controller_golden_test test/rsu/rsu_controller_golden_test.cpp)
