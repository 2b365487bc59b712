# reward targets: palcas_reward, the reward inspector (./palcas reward). nlohmann-json is
# header-only: used here and inside lib/federation (its state file), never in an installed header.
add_executable(palcas_reward tools/reward_inspector.cpp)
target_link_libraries(palcas_reward palcas_core)
install(TARGETS palcas_reward RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
