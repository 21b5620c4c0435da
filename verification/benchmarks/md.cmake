# MD solver benchmarks (Google Benchmark; run in Release, never as a ctest test).
add_executable(bench_md ${CMAKE_CURRENT_SOURCE_DIR}/bench_md.cpp)
target_link_libraries(bench_md PRIVATE shaker_md benchmark::benchmark)

# Cache misses per collision under valgrind (md-cache-lines.sh); built where valgrind's
# client-request header is installed (it only marks the measured stretch).
find_path(CALLGRIND_INCLUDE_DIR valgrind/callgrind.h)
if(CALLGRIND_INCLUDE_DIR)
  add_executable(md_cache_lines ${CMAKE_CURRENT_SOURCE_DIR}/md_cache_lines.cpp)
  target_include_directories(md_cache_lines PRIVATE ${CALLGRIND_INCLUDE_DIR})
  target_link_libraries(md_cache_lines PRIVATE shaker_md)
endif()
