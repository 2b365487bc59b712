# reward tests (test/reward/): one gtest per module, plus one that runs the palcas_reward binary.
palcas_core_add_gtest(rss_test test/reward/rss_test.cpp)
palcas_core_add_gtest(reward_test test/reward/reward_test.cpp)
palcas_core_add_gtest(terminal_rewards_test test/reward/terminal_rewards_test.cpp)
# reward_test also checks that config/reward.yaml lists every RewardParams constant.
target_compile_definitions(reward_test PRIVATE
  PALCAS_REWARD_YAML="${CMAKE_CURRENT_SOURCE_DIR}/../config/reward.yaml")
palcas_core_add_gtest(reward_inspector_test test/reward/reward_inspector_test.cpp)
target_compile_definitions(reward_inspector_test PRIVATE
  PALCAS_REWARD_BIN="$<TARGET_FILE:palcas_reward>")
add_dependencies(reward_inspector_test palcas_reward)
