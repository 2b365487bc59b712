# scenario tests: road spec (checks, sources), network vs sources (generated and hand-written),
# demand writer, and an in-process SUMO smoke run per scenario (libsumo holds one simulation
# per process, hence one executable per scenario).
palcas_sim_add_gtest(road_spec_test test/road_spec_test.cpp)
# Where an RSU stands in the map (pure geometry).
palcas_sim_add_gtest(roadside_test test/roadside_test.cpp)
palcas_sim_add_gtest(scenario_network_test test/scenario_network_test.cpp)
palcas_sim_add_gtest(scenario_demand_test test/scenario_demand_test.cpp)
foreach(scenario tiny paper)
  palcas_sim_add_gtest(scenario_smoke_${scenario}_test test/scenario_smoke_test.cpp)
  if(TARGET scenario_smoke_${scenario}_test)
    target_compile_definitions(scenario_smoke_${scenario}_test PRIVATE
      PALCAS_SMOKE_SCENARIO="${scenario}")
    target_link_libraries(scenario_smoke_${scenario}_test sumocpp)
  endif()
endforeach()
# A user's own road (config/scenarios/curved): the road found in its network, its routes, the
# errors; and the session driving it in-process (libsumo: its own executable).
palcas_sim_add_gtest(own_road_test test/own_road_test.cpp)
palcas_sim_add_session_gtest(own_road_session_test test/own_road_session_test.cpp)
