#!/usr/bin/env bash
# Quick start: installs the Debian packages, builds, and runs arpiped on the embedded default
# (replays the generated capture of a camera over an AprilTag; composited frames go to out/).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh build
rm -rf out
build/apps/arpiped --config configs/arpipe.toml
echo
echo "composited video: out/arpiped.y4m   (play with: ffplay out/arpiped.y4m, or mpv)"
echo "composited PNGs:  out/png/frame_*.png"
echo "per-frame poses:  out/results.jsonl"
