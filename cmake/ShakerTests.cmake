# How every test folder (verification/<folder>, validation, reports) declares its ctest tests.
#
#   shaker_gtest(<target>)
#       the GoogleTest program's tests, found after the build (gtest_discover_tests), named
#       <folder>.<Suite>.<Test>
#   shaker_add_test(NAME <Suite>.<Test> COMMAND <command>... [WORKING_DIRECTORY <dir>])
#       a test that runs a script or program, named <folder>.<Suite>.<Test>
#   shaker_add_pytest(NAME <name> PYTHON <python3> FILE <test file> [ARGS <pytest args>...])
#       a test that runs one file of pytest tests from the repository root, where pytest reads
#       setup.cfg (the package granular_shaker and the tests' helpers import by name) and
#       conftest.py
#
# <folder> is the name of the folder whose CMakeLists.txt calls the function. Which of its tests
# are nightly or known failures, their time limits and environment come from the folder's
# status.txt (format in verification/README.md), not from the CMake files: the first line whose
# pattern matches a test's name gives its labels, timeout and environment. Time limits are
# multiplied by SHAKER_TEST_TIMEOUT_SCALE (10 under the sanitizers, else 1). Script tests also
# find on PYTHONPATH the shared Python helpers of verification/support and the package
# granular_shaker from its source (python/: the validation study, the report generators).
include(GoogleTest)

set(SHAKER_PYTHON_SUPPORT_DIR ${CMAKE_CURRENT_LIST_DIR}/../verification/support)
cmake_path(NORMAL_PATH SHAKER_PYTHON_SUPPORT_DIR)
set(SHAKER_PYTHON_PACKAGE_DIR ${CMAKE_CURRENT_LIST_DIR}/../python)
cmake_path(NORMAL_PATH SHAKER_PYTHON_PACKAGE_DIR)

# Reads the calling folder's status.txt once into directory properties: the number of lines
# and, for each line i, SHAKER_STATUS_<i>_{PATTERN,LABELS,TIMEOUT,ENVIRONMENT}.
function(_shaker_read_status)
  get_directory_property(done SHAKER_STATUS_READ)
  if(done)
    return()
  endif()
  set_directory_properties(PROPERTIES SHAKER_STATUS_READ TRUE SHAKER_STATUS_COUNT 0)
  set(file ${CMAKE_CURRENT_SOURCE_DIR}/status.txt)
  if(NOT EXISTS ${file})
    return()
  endif()
  set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${file})
  cmake_path(GET CMAKE_CURRENT_SOURCE_DIR FILENAME folder)
  file(STRINGS ${file} lines)
  set(count 0)
  set(number 0)
  foreach(line IN LISTS lines)
    math(EXPR number "${number} + 1")
    if(line MATCHES "^[ \t]*(#.*)?$")
      continue()
    endif()
    if(NOT line MATCHES "^([^ \t]+)[ \t]+([^ \t]+)[ \t]+([^ \t]+)[ \t]+([^ \t]+)[ \t]+([^ \t].*)$")
      message(FATAL_ERROR "${file}:${number}: expected PATTERN LABELS TIMEOUT ENVIRONMENT "
                          "REASON, got '${line}'")
    endif()
    set(pattern ${CMAKE_MATCH_1})
    set(labels ${CMAKE_MATCH_2})
    set(timeout ${CMAKE_MATCH_3})
    set(environment ${CMAKE_MATCH_4})
    if(NOT pattern MATCHES "^${folder}\\.")
      message(FATAL_ERROR "${file}:${number}: the pattern '${pattern}' must start with "
                          "'${folder}.', the prefix of this folder's test names")
    endif()
    # `-` (and `default` for the labels) is none; lists are comma-separated.
    foreach(field labels timeout environment)
      if(${field} MATCHES "^(-|default)$")
        set(${field} "")
      endif()
      string(REPLACE "," ";" ${field} "${${field}}")
    endforeach()
    foreach(label IN LISTS labels)
      if(NOT label MATCHES "^(nightly|known-failure|mpi)$")
        message(FATAL_ERROR "${file}:${number}: unknown label '${label}' (default, or a "
                            "comma-separated list of nightly, known-failure, mpi)")
      endif()
    endforeach()
    if(timeout MATCHES "^[0-9]+$")
      math(EXPR timeout "${timeout} * ${SHAKER_TEST_TIMEOUT_SCALE}")
    elseif(NOT timeout STREQUAL "")
      message(FATAL_ERROR "${file}:${number}: the timeout must be whole seconds or -, got "
                          "'${timeout}'")
    endif()
    foreach(key PATTERN LABELS TIMEOUT ENVIRONMENT)
      string(TOLOWER ${key} variable)
      set_directory_properties(PROPERTIES SHAKER_STATUS_${count}_${key} "${${variable}}")
    endforeach()
    math(EXPR count "${count} + 1")
  endforeach()
  set_directory_properties(PROPERTIES SHAKER_STATUS_COUNT ${count})
endfunction()

# The set_tests_properties arguments of status line i (LABELS, TIMEOUT, ENVIRONMENT).
function(_shaker_status_properties i out)
  set(properties "")
  foreach(key LABELS TIMEOUT ENVIRONMENT)
    get_directory_property(value SHAKER_STATUS_${i}_${key})
    if(NOT value STREQUAL "")
      list(APPEND properties ${key} "${value}")
    endif()
  endforeach()
  set(${out} "${properties}" PARENT_SCOPE)
endfunction()

function(shaker_gtest target)
  _shaker_read_status()
  cmake_path(GET CMAKE_CURRENT_SOURCE_DIR FILENAME folder)
  # support/test_directory.hpp names each test's temporary directory after the folder.
  target_compile_definitions(${target} PRIVATE SHAKER_TEST_FOLDER="${folder}")
  get_directory_property(count SHAKER_STATUS_COUNT)
  # One discovery per status line: that line's pattern, less the patterns of the lines above
  # it (GoogleTest filter POSITIVE-NEGATIVE), then the rest with no status. NO_PRETTY_VALUES:
  # a parameterised test keeps GoogleTest's own name, not one with its parameter's value
  # (bytes of an object, addresses among them, which change from build to build).
  set(earlier "")
  set(rest "*")
  if(count GREATER 0)
    math(EXPR last "${count} - 1")
    foreach(i RANGE ${last})
      get_directory_property(pattern SHAKER_STATUS_${i}_PATTERN)
      string(LENGTH "${folder}." prefix_length)
      string(SUBSTRING "${pattern}" ${prefix_length} -1 pattern)
      if(pattern MATCHES "[-:]")
        message(FATAL_ERROR "${CMAKE_CURRENT_SOURCE_DIR}/status.txt: '${pattern}' has a - or :, "
                            "which GoogleTest filters read as separators")
      endif()
      foreach(key LABELS ENVIRONMENT)
        get_directory_property(value SHAKER_STATUS_${i}_${key})
        list(LENGTH value values)
        if(values GREATER 1)
          message(FATAL_ERROR "${CMAKE_CURRENT_SOURCE_DIR}/status.txt: '${folder}.${pattern}' "
                              "gives GoogleTest programs more than one value of ${key}, which "
                              "gtest_discover_tests cannot pass on")
        endif()
      endforeach()
      _shaker_status_properties(${i} properties)
      set(filter "${pattern}")
      if(earlier)
        string(APPEND filter "-${earlier}")
      endif()
      gtest_discover_tests(${target} TEST_PREFIX "${folder}." DISCOVERY_TIMEOUT 60
                           NO_PRETTY_VALUES TEST_FILTER "${filter}" PROPERTIES ${properties})
      if(pattern STREQUAL "*")
        set(rest "")
        break()
      endif()
      if(earlier)
        string(APPEND earlier ":")
      endif()
      string(APPEND earlier "${pattern}")
    endforeach()
  endif()
  if(rest)
    set(filter "*")
    if(earlier)
      set(filter "*-${earlier}")
    endif()
    gtest_discover_tests(${target} TEST_PREFIX "${folder}." DISCOVERY_TIMEOUT 60
                         NO_PRETTY_VALUES TEST_FILTER "${filter}")
  endif()
endfunction()

function(shaker_add_test)
  cmake_parse_arguments(TEST "" "NAME;WORKING_DIRECTORY" "COMMAND" ${ARGN})
  _shaker_read_status()
  cmake_path(GET CMAKE_CURRENT_SOURCE_DIR FILENAME folder)
  set(name ${folder}.${TEST_NAME})
  if(TEST_WORKING_DIRECTORY)
    add_test(NAME ${name} COMMAND ${TEST_COMMAND} WORKING_DIRECTORY ${TEST_WORKING_DIRECTORY})
  else()
    add_test(NAME ${name} COMMAND ${TEST_COMMAND})
  endif()
  set(python_path "PYTHONPATH=path_list_prepend:${SHAKER_PYTHON_SUPPORT_DIR}"
                  "PYTHONPATH=path_list_prepend:${SHAKER_PYTHON_PACKAGE_DIR}")
  set_tests_properties(${name} PROPERTIES ENVIRONMENT_MODIFICATION "${python_path}")
  get_directory_property(count SHAKER_STATUS_COUNT)
  if(count EQUAL 0)
    return()
  endif()
  math(EXPR last "${count} - 1")
  foreach(i RANGE ${last})
    get_directory_property(pattern SHAKER_STATUS_${i}_PATTERN)
    # The glob (* any characters, ? one) as an anchored regular expression.
    string(REGEX REPLACE "([][.+^$()|\\\\{}])" "\\\\\\1" regex "${pattern}")
    string(REPLACE "*" ".*" regex "${regex}")
    string(REPLACE "?" "." regex "${regex}")
    if(name MATCHES "^${regex}$")
      foreach(key LABELS TIMEOUT ENVIRONMENT)
        get_directory_property(value SHAKER_STATUS_${i}_${key})
        if(NOT value STREQUAL "")
          set_tests_properties(${name} PROPERTIES ${key} "${value}")
        endif()
      endforeach()
      break()
    endif()
  endforeach()
endfunction()

function(shaker_add_pytest)
  cmake_parse_arguments(PYTEST "" "NAME;PYTHON;FILE" "ARGS" ${ARGN})
  shaker_add_test(NAME ${PYTEST_NAME}
                  COMMAND ${PYTEST_PYTHON} -m pytest ${PYTEST_FILE} -q ${PYTEST_ARGS}
                  WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
endfunction()
