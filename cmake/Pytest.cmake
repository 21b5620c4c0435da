# shaker_add_pytest(NAME <ctest name> PYTHON <python3> FILE <test file> [ARGS <pytest args>...])
# A ctest that runs one file of pytest tests from the repository root: there the packages
# validation and reports import by name, and pytest reads setup.cfg and conftest.py (the shared
# --shaker option and the work_dir fixture).
function(shaker_add_pytest)
  cmake_parse_arguments(PYTEST "" "NAME;PYTHON;FILE" "ARGS" ${ARGN})
  add_test(NAME ${PYTEST_NAME}
           COMMAND ${PYTEST_PYTHON} -m pytest ${PYTEST_FILE} -q ${PYTEST_ARGS}
           WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
endfunction()
