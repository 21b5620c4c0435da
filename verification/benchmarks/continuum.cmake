# Continuum solver benchmarks (Google Benchmark; Release build; never a ctest).
add_executable(bench_continuum ${CMAKE_CURRENT_LIST_DIR}/bench_continuum.cpp)
target_link_libraries(bench_continuum PRIVATE shaker_continuum benchmark::benchmark)
