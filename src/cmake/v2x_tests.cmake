# v2x tests (test/v2x/): determinism per seed, loss and delay statistics, range, uplink view.
palcas_core_add_gtest(v2x_channel_test test/v2x/v2x_channel_test.cpp)
