#!/usr/bin/env bash
# Quick start: installs the Debian packages, builds what the main job needs (arpiped, arpipe and
# the embedded default capture, not the tests: scripts/test.sh builds everything), and runs arpiped
# on the embedded default (replays the generated capture of a camera over an AprilTag; composited
# frames go to out/). Prints how long it took from the packages to the first composited frame.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
now() { date +%s.%N; }
since() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.0f", b - a }'; }
start=$(now)
# Without the benchmarks (arpipe bench): the test command builds them into the same build/.
ARPIPE_BUILD_TARGETS="arpiped arpipe default_capture" scripts/build.sh build -DARPIPE_BUILD_BENCH=OFF
built=$(now)
rm -rf out
# The first composited frame is the first PNG the daemon writes (written whole, then renamed).
first_frame=$(mktemp)
trap 'rm -f "$first_frame"' EXIT
( until compgen -G "out/png/frame_*.png" >/dev/null; do sleep 0.05; done; now >"$first_frame" ) &
watcher=$!
build/apps/arpiped --config configs/arpipe.toml
done_at=$(now)
kill "$watcher" 2>/dev/null || true
first=$(cat "$first_frame")
echo
echo "built in $(since "$start" "$built") s; the first composited frame $(since "$start" "${first:-$done_at}") s" \
  "and the last $(since "$start" "$done_at") s after the packages were in place"
echo "composited video: out/arpiped.y4m   (play with: ffplay out/arpiped.y4m, or mpv)"
echo "composited PNGs:  out/png/frame_*.png"
echo "per-frame poses:  out/results.jsonl"
