#!/usr/bin/env bash
# The README's test command: installs missing dependencies, configures and builds the Release
# preset, and runs the default ctest set (everything but the labels `nightly` and
# `known-failure`, which each test folder's status.txt assigns: verification/README.md).
set -euo pipefail
cd "$(dirname "$0")/.."
bash ci/install-deps.sh
cmake --preset release > build-configure.log 2>&1 || { cat build-configure.log; exit 1; }
rm -f build-configure.log
cmake --build --preset release
ctest --preset default "$@"
