#!/usr/bin/env bash
# The one list of Debian 12 packages arpipe needs to build, run and test.
# Usage: scripts/install-deps.sh [--tests]   (as root, or with sudo available)
# --tests adds what only the tests need (scripts/test.sh passes it; the quick start does not).
set -euo pipefail
with_tests=0
if [ "${1:-}" = "--tests" ]; then with_tests=1; fi

packages=(
  # toolchain
  build-essential cmake pkg-config ninja-build git
  # core
  libmrcal-dev libdogleg-dev libapriltag-dev libopencv-dev libglm-dev
  libmrgingham-dev libeigen3-dev libsuitesparse-dev
  libtomlplusplus-dev nlohmann-json3-dev libsystemd-dev libfmt-dev
  libgeographiclib-dev
  libbullet-dev  # rigid-body physics against the proxies (core/physics)
  libmeshoptimizer-dev  # proxy simplification (arpipe proxy simplify, core/scene/mesh_simplify)
  # the command lines of arpipe and arpiped (header-only)
  libcli11-dev
  # HDR light probes (OpenEXR) and the PRT cache's content key (xxHash)
  libopenexr-dev libxxhash-dev
  # live cameras: libcamera (ISP pipelines, Raspberry Pi), libjpeg-turbo (MJPEG from UVC webcams)
  libcamera-dev libturbojpeg0-dev
  # live outputs: the HTTP preview, MJPEG, snapshots, state and Prometheus metrics
  libmicrohttpd-dev
  # live outputs: the GStreamer sink (files, RTSP, encoders) with the common elements
  libgstreamer1.0-dev libgstreamer-plugins-base1.0-dev gstreamer1.0-plugins-base
  gstreamer1.0-plugins-good gstreamer1.0-plugins-ugly gstreamer1.0-rtsp
  # 360-degree video backgrounds: FFmpeg's demuxers, decoders and scaler
  libavformat-dev libavcodec-dev libswscale-dev libavutil-dev
  # render: EGL + GLES 3 on Mesa (llvmpipe when there is no GPU)
  libegl-dev libgles-dev libegl-mesa0 libgl1-mesa-dri libgbm1
  libtinygltf-dev libembree-dev libstb-dev libpng-dev
  # tests
  libgtest-dev libgmock-dev librapidcheck-dev
  # mrcal's own tools: tests check our camera model against them
  mrcal python3-mrcal
  # their plots (mrcal-show-*), written to files without a display
  gnuplot-nox
  # the V4L2 stand-in's tests: v4l2-ctl and v4l2-compliance against it
  v4l-utils
  # checking the Y4M output plays
  ffmpeg
  # the live outputs' tests: the preview page in a real headless browser, promtool (Prometheus'
  # own checker) on /metrics
  chromium-headless-shell prometheus
  # the GStreamer sink's RTSP round trip (a gst-rtsp-server in the test)
  libgstrtspserver-1.0-dev
)

# Only for the tests: OpenCV's 13 sample photographs of a chessboard (tests/calib/real_photographs_test.cpp).
test_packages=(opencv-doc)
photographs=/usr/share/doc/opencv-doc/examples/data
if [ "$with_tests" = 1 ]; then packages+=("${test_packages[@]}"); fi

sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then sudo_cmd=(sudo); fi

# A minimal image's dpkg config may leave out /usr/share/doc: then the photographs are unpacked
# from the package itself.
unpack_photographs() {
  if [ "$with_tests" = 1 ] && [ ! -f "$photographs/left01.jpg" ]; then
    local tmp
    tmp=$(mktemp -d)
    (cd "$tmp" && apt-get download -qq opencv-doc)
    dpkg-deb --fsys-tarfile "$tmp"/opencv-doc_*.deb |
      "${sudo_cmd[@]}" tar -x -C / --wildcards ".$photographs/left*.jpg"
    rm -rf "$tmp"
  fi
}

export DEBIAN_FRONTEND=noninteractive
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages already installed"
  unpack_photographs
  exit 0
fi
echo "install-deps: installing ${missing[*]}"
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
unpack_photographs
