# learning targets: palcas_bench (Google Benchmark runs the timings, it writes JSON; run by
# ./palcas bench)
find_package(benchmark REQUIRED)
add_executable(palcas_bench bench/palcas_bench.cpp)
target_link_libraries(palcas_bench palcas_core benchmark::benchmark)
target_compile_options(palcas_bench PRIVATE ${PALCAS_CORE_COMPILE_OPTIONS})
# The flags the numbers were measured with go into the JSON.
string(REPLACE ";" " " PALCAS_BENCH_FLAGS "${CMAKE_CXX_FLAGS_RELEASE} ${PALCAS_CORE_COMPILE_OPTIONS} -fopenmp")
target_compile_definitions(palcas_bench PRIVATE PALCAS_BENCH_FLAGS="${PALCAS_BENCH_FLAGS}")
install(TARGETS palcas_bench RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
