# metrics tests (test/metrics/): one gtest per module. The tests that check the C++ codes
# against the message constants read palcas_msgs/msg/*.msg as text (no ROS header is included).
set(PALCAS_METRICS_MSG_DIR "${CMAKE_CURRENT_SOURCE_DIR}/../palcas_msgs/msg")
palcas_core_add_gtest(outcome_tracker_test test/metrics/outcome_tracker_test.cpp)
palcas_core_add_gtest(episode_metrics_test test/metrics/episode_metrics_test.cpp)
palcas_core_add_gtest(advisory_validator_test test/metrics/advisory_validator_test.cpp)
foreach(test_target outcome_tracker_test advisory_validator_test)
  if(TARGET ${test_target})
    target_compile_definitions(${test_target} PRIVATE
      PALCAS_MSG_DIR="${PALCAS_METRICS_MSG_DIR}")
  endif()
endforeach()
