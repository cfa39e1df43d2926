# Every external dependency, found once (packages listed in scripts/install-deps.sh).
find_package(PkgConfig REQUIRED)
find_package(Threads REQUIRED)
find_package(OpenCV 4 REQUIRED COMPONENTS core imgproc calib3d imgcodecs)
find_package(apriltag REQUIRED)
find_package(nlohmann_json 3 REQUIRED)
find_package(ZLIB REQUIRED)
find_package(PNG REQUIRED)  # simulator textures: PNG decoded by libpng, not by OpenCV's format probing
find_package(embree 3 REQUIRED)  # target: embree (the simulator's ray caster)
find_package(fmt REQUIRED)
find_package(meshoptimizer REQUIRED)  # target: meshoptimizer::meshoptimizer (proxy simplification)
pkg_check_modules(TOMLPP REQUIRED IMPORTED_TARGET tomlplusplus)
pkg_check_modules(SYSTEMD REQUIRED IMPORTED_TARGET libsystemd)
pkg_check_modules(EGL REQUIRED IMPORTED_TARGET egl)
pkg_check_modules(GLES REQUIRED IMPORTED_TARGET glesv2)
pkg_check_modules(GEOGRAPHICLIB REQUIRED IMPORTED_TARGET geographiclib)  # sun direction in local East-North-Up
pkg_check_modules(LIBCAMERA REQUIRED IMPORTED_TARGET libcamera)  # live cameras behind an ISP (Raspberry Pi)
pkg_check_modules(TURBOJPEG REQUIRED IMPORTED_TARGET libturbojpeg)  # MJPEG from UVC webcams
pkg_check_modules(OPENEXR REQUIRED IMPORTED_TARGET OpenEXR)  # HDR light probes (.exr)
pkg_check_modules(XXHASH REQUIRED IMPORTED_TARGET libxxhash)  # the PRT cache key: a hash of the mesh content
pkg_check_modules(MICROHTTPD REQUIRED IMPORTED_TARGET libmicrohttpd)  # the live HTTP outputs (preview, MJPEG, metrics)
pkg_check_modules(GSTREAMER REQUIRED IMPORTED_TARGET gstreamer-1.0 gstreamer-app-1.0)  # sinks.gstreamer: files, RTSP, encoders
pkg_check_modules(FFMPEG REQUIRED IMPORTED_TARGET libavformat libavcodec libswscale libavutil)  # panorama videos

# mrcal ships no pkg-config or CMake file; -lmrcal pulls in libdogleg and CHOLMOD.
find_library(MRCAL_LIBRARY mrcal REQUIRED)
find_path(MRCAL_INCLUDE_DIR mrcal/mrcal.h REQUIRED)
add_library(mrcal::mrcal UNKNOWN IMPORTED)
set_target_properties(mrcal::mrcal PROPERTIES IMPORTED_LOCATION ${MRCAL_LIBRARY}
  INTERFACE_INCLUDE_DIRECTORIES ${MRCAL_INCLUDE_DIR})

# mrgingham (chessboard corners, square boards) ships neither pkg-config nor CMake files either.
find_library(MRGINGHAM_LIBRARY mrgingham REQUIRED)
find_path(MRGINGHAM_INCLUDE_DIR mrgingham/mrgingham.hh REQUIRED)
add_library(mrgingham::mrgingham UNKNOWN IMPORTED)
set_target_properties(mrgingham::mrgingham PROPERTIES IMPORTED_LOCATION ${MRGINGHAM_LIBRARY}
  INTERFACE_INCLUDE_DIRECTORIES ${MRGINGHAM_INCLUDE_DIR})
# Eigen: dense linear algebra for the calibration's uncertainty (header-only).
find_package(Eigen3 3.3 REQUIRED NO_MODULE)

# tinygltf is header-only in Debian (tiny_gltf.h); it needs stb and nlohmann json.
find_path(TINYGLTF_INCLUDE_DIR tiny_gltf.h PATH_SUFFIXES tinygltf REQUIRED)

if(ARPIPE_BUILD_TESTS)
  find_package(GTest REQUIRED)
  # The GStreamer sink's RTSP round trip: a gst-rtsp-server in the test receives what it sends.
  pkg_check_modules(GST_RTSP_SERVER REQUIRED IMPORTED_TARGET gstreamer-rtsp-server-1.0 gstreamer-app-1.0 gstreamer-rtp-1.0)
endif()
