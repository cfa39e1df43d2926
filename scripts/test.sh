#!/usr/bin/env bash
# Installs the Debian packages, builds, and runs every test (unit, end-to-end, bad input).
# Usage: scripts/test.sh [BUILD_DIR] [-DOPTION=VALUE]...
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=${1:-build}
shift || true
scripts/install-deps.sh --tests
# The benchmarks are built (and their command-line tests run) even where the quick start left them out.
scripts/build.sh "$build_dir" -DARPIPE_BUILD_BENCH=ON "$@"
ctest --test-dir "$build_dir" --output-on-failure -j 2
