# `shaker analyze` benchmark (Google Benchmark; Release build; never a ctest).
add_executable(bench_analysis ${CMAKE_CURRENT_LIST_DIR}/bench_analysis.cpp)
target_link_libraries(bench_analysis PRIVATE shaker_analysis benchmark::benchmark)
