# MD solver benchmarks (Google Benchmark; run in Release, never as a ctest test).
add_executable(bench_md ${CMAKE_CURRENT_SOURCE_DIR}/bench_md.cpp)
target_link_libraries(bench_md PRIVATE shaker_md benchmark::benchmark)
