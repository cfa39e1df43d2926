#!/usr/bin/env bash
# Installs the Debian packages, builds, and runs every test (unit, end-to-end, bad input).
# Usage: scripts/test.sh [BUILD_DIR] [-DOPTION=VALUE]...
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=${1:-build}
shift || true
scripts/install-deps.sh
scripts/build.sh "$build_dir" "$@"
ctest --test-dir "$build_dir" --output-on-failure -j 2
