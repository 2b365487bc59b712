# common tests (test/common/): one gtest per module
palcas_core_add_gtest(action_test test/common/action_test.cpp)
palcas_core_add_gtest(rng_test test/common/rng_test.cpp)
# message authentication: HMAC-SHA256 vectors, tampering, key files
palcas_core_add_gtest(message_auth_test test/common/message_auth_test.cpp)
# the one atomic file write: replace whole or keep the old file, errors name the file
palcas_core_add_gtest(atomic_file_test test/common/atomic_file_test.cpp)
# the shared input checks: the texts they throw
palcas_core_add_gtest(checks_test test/common/checks_test.cpp)
# the road's one vocabulary: codes, names, bad codes refused
palcas_core_add_gtest(road_terms_test test/common/road_terms_test.cpp)
# what the core was built for: Eigen's instruction sets as its users see them, the CPU
palcas_core_add_gtest(build_info_test test/common/build_info_test.cpp)
target_compile_definitions(build_info_test PRIVATE PALCAS_CORE_ARCH_EXPECTED="${PALCAS_CORE_ARCH_NAME}")
