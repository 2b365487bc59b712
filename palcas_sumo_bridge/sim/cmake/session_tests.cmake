palcas_sim_add_gtest(road_layout_test test/road_layout_test.cpp)
palcas_sim_add_gtest(lockstep_test test/lockstep_test.cpp)
palcas_sim_add_gtest(advisory_holds_test test/advisory_holds_test.cpp)
palcas_sim_add_gtest(run_recorder_test test/run_recorder_test.cpp)
# The tests that drive SUMO through the session.
foreach(test sumo_session advice_guard insertion_dropped assist_mode busy_handback
        busy_change_bound collision_attribution busy_at_start sumo_outputs episode_runner)
  palcas_sim_add_session_gtest(${test}_test test/${test}_test.cpp)
endforeach()
# The insertion guard on and off: one source, two executables.
palcas_sim_add_session_gtest(insertion_guard_test test/insertion_guard_test.cpp)
palcas_sim_add_session_gtest(insertion_guard_off_test test/insertion_guard_test.cpp)
if(TARGET insertion_guard_off_test)
  target_compile_definitions(insertion_guard_off_test PRIVATE PALCAS_GUARD_OFF)
endif()
