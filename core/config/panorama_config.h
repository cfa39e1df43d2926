// [source.panorama]: a 360° panorama as the background (seed 003's hybrid viewer), seen through a
// view camera turned over time. The panorama is placed in the world as an environment image is
// (core/environment/environment_layout.h, "equirect"; hdr_environment.h, default_world_from_probe):
// its centre column looks along world +y, its top row is world +z, turning right moves right.
#pragma once

#include <cstdint>
#include <filesystem>
#include <numbers>
#include <vector>

#include "core/config/choice_names.h"
#include "core/config/config_rules.h"
#include "core/geometry/ods_projection.h"
#include "core/geometry/vec.h"

namespace arpipe {

// How the image holds the sphere (source.panorama.layout): one equirectangular image (2:1), or
// an omnidirectional-stereo pair (core/geometry/ods_projection.h), each eye 2:1, the left eye's on
// top (1:1 in all) or on the left (4:1). Auto: what a video's spherical metadata says, else what
// the shape holds (2:1 mono, 1:1 top/bottom, 4:1 left/right).
enum class PanoramaLayout { Auto, Equirect, EquirectTopBottom, EquirectLeftRight };
inline constexpr ChoiceName<PanoramaLayout> kPanoramaLayoutNames[] = {{"auto", PanoramaLayout::Auto},
                                                                      {"equirect", PanoramaLayout::Equirect},
                                                                      {"equirect-tb", PanoramaLayout::EquirectTopBottom},
                                                                      {"equirect-lr", PanoramaLayout::EquirectLeftRight}};
inline bool is_stereo(PanoramaLayout layout) {
  return layout == PanoramaLayout::EquirectTopBottom || layout == PanoramaLayout::EquirectLeftRight;
}
// The layout a width x height image holds by its shape (Equirect for any shape but 1:1 and 4:1).
inline PanoramaLayout layout_of_shape(int width, int height) {
  if (width == height) return PanoramaLayout::EquirectTopBottom;
  if (int64_t{width} == 4 * int64_t{height}) return PanoramaLayout::EquirectLeftRight;
  return PanoramaLayout::Equirect;
}

// What the sinks get from a stereo layout (source.panorama.view.stereo_output): each eye's picture
// as its own frame, or the two in one frame, the left eye's on top or on the left.
enum class StereoOutput { Frames, TopBottom, LeftRight };
inline constexpr ChoiceName<StereoOutput> kStereoOutputNames[] = {
    {"frames", StereoOutput::Frames}, {"tb", StereoOutput::TopBottom}, {"lr", StereoOutput::LeftRight}};

// The camera that looks at the panorama, and where it looks over time.
struct PanoramaViewConfig {
  std::filesystem::path camera_model;  // an mrcal .cameramodel; empty: a pinhole of width, height, hfov
  int width = 1280;
  int height = 720;
  double hfov_rad = std::numbers::pi / 2;
  double fps = 30;
  int64_t frames = 0;                  // 0: without end
  // Yaw 0, pitch 0 look at the panorama's centre with its top up; yaw > 0 turns right, pitch > 0 up
  // (90: the zenith). The yaw sweeps at yaw_rad_per_s (the seed's protocol: 12 degrees/s).
  double yaw_rad = 0;
  double yaw_rad_per_s = 0;
  double pitch_rad = 0;
  // Or a head-pose track file (capture/panorama/head_pose_track.h): the orientation over time, turned
  // right by yaw_rad; yaw_rad_per_s and pitch_rad must then stay 0.
  std::filesystem::path track;
  // With more than one viewpoint: seconds at each before the view moves to the next (and from the
  // last back to the first); the sweep starts again at each. The seed's protocol: 60 (720 degrees
  // at 12 degrees/s).
  double dwell_s = 0;
  StereoOutput stereo_output = StereoOutput::TopBottom;

  bool operator==(const PanoramaViewConfig&) const = default;
};

template <class V>
void visit(V& v, PanoramaViewConfig& s) {
  v.key("camera_model", s.camera_model, "an mrcal .cameramodel for the view; \"\": a pinhole of width, height and hfov_deg");
  v.key("width", s.width, IntRange{2, 16384}, "the view's width without camera_model");
  v.key("height", s.height, IntRange{2, 16384}, "the view's height without camera_model");
  v.key("hfov_deg", s.hfov_rad, Degrees{NumberRange::open_closed(0, 170)}, "the pinhole view's horizontal field of view");
  v.key("fps", s.fps, NumberRange::open_closed(0, 1000), "frames a second (frame times are index / fps)");
  v.key("frames", s.frames, IntRange{0, 1'000'000'000}, "frames to give; 0 = without end");
  v.key("yaw_deg", s.yaw_rad, Degrees{NumberRange::closed(-1e6, 1e6)}, "where the first frame looks: right of the centre");
  v.key("yaw_deg_per_s", s.yaw_rad_per_s, Degrees{NumberRange::closed(-1e5, 1e5).in("degrees/s")},
        "the yaw's sweep (the seed's protocol: 12)");
  v.key("pitch_deg", s.pitch_rad, Degrees{NumberRange::closed(-90, 90)}, "up from the horizon (90 = the zenith)");
  v.key("track", s.track, "a head-pose track file (t_s with yaw_deg, pitch_deg, roll_deg or qw, qx, qy, qz) instead of the sweep");
  v.key("dwell_s", s.dwell_s, NumberRange::closed(0, 1e6).in("s"),
        "with [[source.panorama.viewpoints]]: time at each viewpoint before the next (the seed's protocol: 60)");
  v.key("stereo_output", s.stereo_output, kStereoOutputNames,
        "stereo layouts: the sinks get both eyes in one frame, left on top (tb) or left (lr), or each eye's frame (frames)");
}

// Another place a panorama was taken (seed 003's teleport points), visited after the one before.
// Its proxies are those whose render.proxies.viewpoints name it (or name none).
struct PanoramaViewpoint {
  std::filesystem::path file;
  Vec3 position_m{0, 0, 0};
  double yaw_rad = 0;
  double hdr_scale = 1;

  bool operator==(const PanoramaViewpoint&) const = default;
};

template <class V>
void visit(V& v, PanoramaViewpoint& s) {
  v.key("file", s.file, "a still or a video, as source.panorama.file (same layout)");
  v.key("position_m", s.position_m, "where in the world it was taken");
  v.key("yaw_deg", s.yaw_rad, Degrees{NumberRange::closed(-360, 360)}, "its turn about world z");
  v.key("hdr_scale", s.hdr_scale, NumberRange::open_closed(0, 1e12), "HDR files: radiance to display value (1 = white)");
}

struct PanoramaConfig {
  // A still: PNG, JPEG (8-bit sRGB), Radiance .hdr or OpenEXR .exr; or a video (.mp4, .m4v, .mov,
  // .mkv, .webm: H.264, HEVC, VP8, VP9, AV1), looped.
  std::filesystem::path file;
  PanoramaLayout layout = PanoramaLayout::Auto;
  Vec3 position_m{0, 0, 0};            // where in the world it was taken (the view camera's centre)
  double yaw_rad = 0;                  // its turn about world z (as light.environment.yaw_deg)
  double hdr_scale = 1;                // .hdr / .exr: the file's radiance to display values (1.0 = white)
  // A stereo layout's capture: the distance between its eyes, and the elevations over which it
  // brought them together towards the poles (core/geometry/ods_projection.h).
  double ipd_m = 0.064;
  double pole_merge_from_rad = 60 * std::numbers::pi / 180;
  double pole_merge_to_rad = 75 * std::numbers::pi / 180;
  // Videos: the board's V4L2 memory-to-memory decoder first, where it has one (software otherwise).
  bool hardware_decoding = true;
  PanoramaViewConfig view;
  // Viewpoints 1, 2, ... (this table's own file, position and yaw are viewpoint 0).
  std::vector<PanoramaViewpoint> viewpoints;
  static constexpr size_t kMaxViewpoints = 64;

  // Viewpoint k (0: this table's own), k < viewpoint_count().
  PanoramaViewpoint viewpoint(size_t k) const {
    return k == 0 ? PanoramaViewpoint{file, position_m, yaw_rad, hdr_scale} : viewpoints.at(k - 1);
  }
  size_t viewpoint_count() const { return 1 + viewpoints.size(); }
  OdsRig ods_rig() const { return {ipd_m, pole_merge_from_rad, pole_merge_to_rad}; }

  bool operator==(const PanoramaConfig&) const = default;
};

template <class V>
void visit(V& v, PanoramaConfig& s) {
  v.key("file", s.file, "a still (PNG, JPEG, .hdr, .exr) or a looped video (.mp4, .mov, .mkv, .webm: H.264, HEVC, VP8, VP9, AV1)");
  v.key("layout", s.layout, kPanoramaLayoutNames,
        "how the image holds the sphere: equirect (2:1, mono), equirect-tb or equirect-lr (omnidirectional stereo, "
        "the left eye on top or on the left), auto (a video's metadata, else the shape: 2:1, 1:1, 4:1)");
  v.key("position_m", s.position_m, "where in the world it was taken (the view's centre)");
  v.key("yaw_deg", s.yaw_rad, Degrees{NumberRange::closed(-360, 360)}, "its turn about world z (0: the centre looks along +y)");
  v.key("hdr_scale", s.hdr_scale, NumberRange::open_closed(0, 1e12), "HDR files: radiance to display value (1 = white)");
  v.key("ipd_m", s.ipd_m, NumberRange::open_closed(0, 1).in("m"), "stereo layouts: the capture's distance between the eyes");
  v.key("pole_merge_from_deg", s.pole_merge_from_rad, Degrees{NumberRange::closed(0, 90)},
        "stereo layouts: the elevation up to which the capture kept the eyes ipd_m apart");
  v.key("pole_merge_to_deg", s.pole_merge_to_rad, Degrees{NumberRange::closed(0, 90)},
        "stereo layouts: the elevation from which it had brought them together (a raised-cosine fall between)");
  v.key("hardware_decoding", s.hardware_decoding,
        "videos: decode with the board's V4L2 memory-to-memory decoder (FFmpeg's <codec>_v4l2m2m) where it has one, "
        "software otherwise");
  v.section("view", s.view, "the camera that looks at the panorama");
  v.sections("viewpoints", s.viewpoints, "more places, each its own panorama: [[source.panorama.viewpoints]], visited in turn");
}

}  // namespace arpipe
