# state tests (test/state/): one gtest per module.
palcas_core_add_gtest(state_layout_test test/state/state_layout_test.cpp)
palcas_core_add_gtest(neighbours_test test/state/neighbours_test.cpp)
palcas_core_add_gtest(state_builder_test test/state/state_builder_test.cpp)
