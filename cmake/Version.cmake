# The git commit is read at build time, not configure time, so that a binary built after a
# new commit records that commit. The generated file is rewritten only when it changes.
set(SHAKER_VERSION_CPP ${CMAKE_BINARY_DIR}/generated/version.cpp)
add_custom_target(shaker_version_stamp
  COMMAND ${CMAKE_COMMAND}
    -DSOURCE_DIR=${CMAKE_SOURCE_DIR}
    -DOUTPUT=${SHAKER_VERSION_CPP}
    -DVERSION=${PROJECT_VERSION}
    -P ${CMAKE_SOURCE_DIR}/cmake/WriteVersion.cmake
  BYPRODUCTS ${SHAKER_VERSION_CPP}
  COMMENT "Recording the git commit")
