#!/usr/bin/env bash
# Configures and builds arpipe into a build directory (default: build/). Extra args go to cmake.
# Usage: scripts/build.sh [BUILD_DIR] [-DOPTION=VALUE]...
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=${1:-build}
shift || true
werror=OFF
if [ "${CI:-}" = "true" ]; then werror=ON; fi
generator=()
if command -v ninja >/dev/null 2>&1; then generator=(-G Ninja); fi
# A unity build of the libraries and programs: about half the compile time (docs/ARCHITECTURE.md).
# -g1: line tables only, so backtraces and perf still name the file and line, at about a third
# less compile time than -g (tests/e2e/arpipe_cli_test.cpp, GCC 12: 8.0-9.9 s user with -g, 6.2-6.5
# with -g1 or -g0); the code is the same. Pass your own -DCMAKE_CXX_FLAGS_RELWITHDEBINFO to debug.
cmake -S . -B "$build_dir" "${generator[@]}" -DARPIPE_WERROR=$werror -DARPIPE_UNITY_BUILD=ON \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" "$@"
# ARPIPE_BUILD_TARGETS: build only these targets (CI's sanitizer tree), else everything.
cmake --build "$build_dir" -j "$(nproc)" ${ARPIPE_BUILD_TARGETS:+--target $ARPIPE_BUILD_TARGETS}
