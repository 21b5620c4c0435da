# require_package(<Name> <debian-package> [CONFIG] [COMPONENTS ...])
# find_package that fails with the Debian package to install instead of CMake's generic text.
macro(require_package name debian_package)
  find_package(${name} ${ARGN} QUIET)
  if(NOT ${name}_FOUND)
    message(FATAL_ERROR
      "granular-shaker needs ${name}, which was not found. "
      "Install the Debian package '${debian_package}' (or run ci/install-deps.sh).")
  endif()
endmacro()
