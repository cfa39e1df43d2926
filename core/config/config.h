// The daemon's configuration: a TOML file where every key has a default and unknown keys are errors.
// Degrees appear only here, at the boundary; the structs hold radians and metres.
#pragma once

#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/config/config_rules.h"
#include "core/config/blur_method.h"
#include "core/config/egl_platform_request.h"
#include "core/config/lens_mode.h"
#include "core/config/log_level_names.h"
#include "core/config/source_choices.h"
#include "core/config/light_source.h"
#include "core/config/object_prt.h"
#include "core/config/panorama_config.h"
#include "core/config/physics_choices.h"
#include "core/config/proxy_roles.h"
#include "core/config/raw_colour_config.h"
#include "core/config/probe_kind.h"
#include "core/config/probe_method.h"
#include "core/config/shadow_method.h"
#include "core/config/v4l2_output_format.h"
#include "core/geometry/vec.h"
#include "core/environment/environment_layout.h"
#include "core/image/camera_response.h"
#include "core/sh/sh_window.h"

namespace arpipe {

// Bad config input; what() names the file, the line and column where known, and what was expected.
class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct SourceConfig {
  SourceType type = SourceType::Replay;
  std::filesystem::path path;           // replay: the recording directory
  ReplayPacing pacing = ReplayPacing::Timestamps;  // replay only
  bool loop = false;                    // replay: start again at the end (soak tests)
  int loop_cache_mb = 64;               // replay with loop: frames kept in memory after their first pass
  int64_t timestamp_offset_ns = 0;      // added to every exposure_start_ns of this camera
  std::filesystem::path camera_model;   // overrides the recording's camera model; live: required to track

  // Live cameras (v4l2, libcamera). 0 or "auto": whatever the camera offers first.
  std::string device;                   // v4l2: /dev/videoN or a /dev/v4l/by-id|by-path link
  std::string camera;                   // libcamera: camera id, or its index in the list ("" = first)
  StreamRole role = StreamRole::Video;  // libcamera only
  int width = 0;
  int height = 0;
  double fps = 0;
  CaptureFormat pixel_format = CaptureFormat::Auto;  // MJPG: v4l2 only, decoded to RGB24
  int buffers = 4;                      // capture buffers (at least 4)
  int64_t exposure_us = 0;              // manual exposure; 0: auto exposure
  double gain = 0;                      // manual analogue gain (1 = unity); 0: auto
  double gain_unity = 100;              // v4l2: the gain control's value that means gain 1
  // v4l2: what the buffer timestamps mean when the driver does not say (no TSTAMP_SRC flag), or
  // "auto" to take the driver's flag (end-of-frame when it gives none).
  BufferTimestamps timestamp_meaning = BufferTimestamps::DriverFlag;
  int64_t readout_ns = 0;               // rolling-shutter readout (first to last row); 0: global
  int64_t frame_timeout_ms = 1000;      // a frame later than this is a timeout (counted)
  int64_t reconnect_min_ms = 100;       // first retry after a camera disappeared
  int64_t reconnect_max_ms = 5000;      // retries back off up to this
  PanoramaConfig panorama;              // type = "panorama"
  RawColourConfig raw;                  // raw Bayer frames: black level, white balance, colour matrix

  bool operator==(const SourceConfig&) const = default;
};

// Its keys, one row each: the name in the file, the member (whose initializer is the default), the
// rule the value must meet, and the help `arpipe config --defaults` prints (docs/ARCHITECTURE.md, "Adding a config key").
template <class V>
void visit(V& v, SourceConfig& s) {
  v.key("type", s.type, kSourceTypeNames, "a recording, a V4L2 device, a libcamera camera or a 360° panorama");
  v.key("path", s.path, "replay: the recording directory");
  v.key("pacing", s.pacing, kReplayPacingNames, "replay: real time, or as fast as the pipeline runs");
  v.key("loop", s.loop, "replay: start again at the end (soak tests)");
  v.key("loop_cache_mb", s.loop_cache_mb, IntRange{0, 65536},
        "replay with loop: a recording whose frames fit in this many MiB is read and checked once and its "
        "later passes come from memory; 0: read and checked every pass");
  // Drivers disagree about their timestamps by a frame or two; an hour keeps every exposure time
  // plus the offset inside int64 nanoseconds.
  v.key("timestamp_offset_ns", s.timestamp_offset_ns, IntRange{-3'600'000'000'000, 3'600'000'000'000},
        "added to every exposure start of this camera");
  v.key("camera_model", s.camera_model, "a .cameramodel to use instead of the recording's (live: needed to track)");
  v.key("device", s.device, "v4l2: /dev/videoN or a /dev/v4l/by-id or by-path link");
  v.key("camera", s.camera, "libcamera: a camera id or index (\"\": the first)");
  v.key("role", s.role, kStreamRoleNames, "libcamera stream role");
  v.key("width", s.width, IntRange{0, 16384}, "live: 0 = the camera's first size");
  v.key("height", s.height, IntRange{0, 16384}, "live: 0 = the camera's first size");
  v.key("fps", s.fps, NumberRange::at_least(0), "live: 0 = the camera's default rate");
  v.key("pixel_format", s.pixel_format, kCaptureFormatNames,
        "live: MJPG is decoded to RGB24; auto: what the camera offers first");
  // Fewer than 4 starves the driver while one buffer is being converted.
  v.key("buffers", s.buffers, IntRange{4, 32}, "capture buffers");
  v.key("exposure_us", s.exposure_us, IntRange{0, 60'000'000}, "manual exposure; 0 = auto exposure");
  v.key("gain", s.gain, NumberRange::at_least(0), "manual analogue gain (1 = unity); 0 = auto");
  v.key("gain_unity", s.gain_unity, NumberRange::above(0), "v4l2: the gain control value that means gain 1");
  v.key("timestamp_meaning", s.timestamp_meaning, kBufferTimestampsNames,
        "live: what the camera's timestamps mean; auto: V4L2's flag, libcamera's documented start of exposure");
  v.key("readout_ns", s.readout_ns, IntRange{0, 1'000'000'000}, "rolling-shutter readout time; 0 = global shutter");
  v.key("frame_timeout_ms", s.frame_timeout_ms, IntRange{1, 600'000}, "a frame later than this is a timeout");
  v.key("reconnect_min_ms", s.reconnect_min_ms, IntRange{1, 600'000}, "first retry after the camera went away");
  v.key("reconnect_max_ms", s.reconnect_max_ms, IntRange{1, 3'600'000}, "retries back off up to this (>= reconnect_min_ms)");
  v.section("panorama", s.panorama, "type = \"panorama\": a 360° still seen through a turning view camera");
  v.section("raw", s.raw, "raw Bayer frames (any source): how their codes become light");
}

// One tag of the anchor bundle: where its centre sits in the world (anchor) frame and how it is turned.
struct BundleTag {
  int id = 0;
  double size_m = 0.1;      // edge between the black and white borders (AprilTag's "tag size")
  Vec3 center_m{0, 0, 0};   // tag centre in the world frame
  double yaw_rad = 0;       // rotation about world z of the tag's x axis; tags lie in the z=0 plane

  bool operator==(const BundleTag&) const = default;
};

// Its keys, one row each: the name in the file, the member (whose initializer is the default), the
// rule the value must meet, and the help `arpipe config --defaults` prints (docs/ARCHITECTURE.md, "Adding a config key").
template <class V>
void visit(V& v, BundleTag& s) {
  // Its range depends on the family: checked after the rows (config_reader.cpp).
  v.key("id", s.id, IntRange{}, "unique, and in [0, the family's code count)");
  v.key("size_m", s.size_m, NumberRange::above(0), "edge of the black square (AprilTag's tag size)");
  v.key("center_m", s.center_m, "tag centre in the world frame");
  v.key("yaw_deg", s.yaw_rad, Degrees{}, "turn of the tag's x axis about world z");
}

struct TrackConfig {
  bool enabled = true;
  std::string family = "tag36h11";
  std::vector<BundleTag> bundle{BundleTag{}};  // default: tag 0, 10 cm, at the origin
  double quad_decimate = 2.0;
  double quad_sigma = 0.0;
  int threads = 1;
  int max_hamming = 1;
  double min_decision_margin = 20.0;
  // IPPE returns two poses for a planar target; when their reprojection errors are within this
  // ratio the choice is ambiguous and temporal consistency decides.
  double ambiguity_ratio = 3.0;
  // Re-fit the tag's border edges in linear light before solving: libapriltag's corners sit about
  // 0.2 px inside the true ones (bench/pose_accuracy measures what this buys and costs).
  bool refine_corners = true;
  // Frames without a detection that still get a pose, predicted at constant velocity from the last
  // two measured ones (state Predicted); beyond this the state is Lost. 0: no prediction.
  int max_predicted_frames = 3;
  // While the previous frame was tracked, look for the tags only in a window around where the
  // bundle is expected (the whole frame when that finds fewer of its tags than should be in view).
  bool search_window = true;
  // A frame whose tags' patch moved less than this (pixels, at the patch's corners, since the last
  // detection) keeps the last detection's pose without detecting again. 0: detect every frame.
  double still_px = 0.05;

  bool operator==(const TrackConfig&) const = default;
};

// Its keys, one row each: the name in the file, the member (whose initializer is the default), the
// rule the value must meet, and the help `arpipe config --defaults` prints (docs/ARCHITECTURE.md, "Adding a config key").
template <class V>
void visit(V& v, TrackConfig& s) {
  v.key("enabled", s.enabled, "find the anchor's tags and the camera's pose");
  v.key("family", s.family, TagFamilyName{}, "libapriltag's tag family");
  v.key("quad_decimate", s.quad_decimate, NumberRange::at_least(1), "find quads in an image this many times smaller");
  // Negative sharpens in libapriltag, so any value goes.
  v.key("quad_sigma", s.quad_sigma, "blur before finding quads (negative sharpens)");
  v.key("threads", s.threads, IntRange{1, 64}, "detector threads");
  // libapriltag corrects at most 3 bits.
  v.key("max_hamming", s.max_hamming, IntRange{0, 3}, "bit errors corrected");
  v.key("min_decision_margin", s.min_decision_margin, NumberRange::at_least(0), "weaker detections are ignored");
  v.key("ambiguity_ratio", s.ambiguity_ratio, NumberRange::at_least(1),
        "IPPE's two poses closer than this error ratio are ambiguous");
  v.key("refine_corners", s.refine_corners, "re-fit the tag borders in linear light (libapriltag's corners sit ~0.2 px inside)");
  // A second of prediction at 30 fps is already far beyond what constant velocity predicts well.
  v.key("max_predicted_frames", s.max_predicted_frames, IntRange{0, 30},
        "frames without a detection whose pose is predicted at constant velocity (0: none)");
  v.key("search_window", s.search_window,
        "after a tracked frame, search only around where the bundle is expected (the whole frame when that falls short)");
  v.key("still_px", s.still_px, NumberRange::closed(0, 1).in("pixels"),
        "a frame whose tags moved less than this (pixels) since the last detection keeps its pose (0: detect every frame)");
  v.sections("bundle", s.bundle, "the anchor: one [[track.bundle]] per tag, placed in the world (anchor) frame, lying in z = 0");
}

// The shutter-motion stage (core/motion): the camera's poses over each exposure.
struct MotionConfig {
  bool enabled = true;  // runs only while tracking is on
  // 0: the output may not lag, so the end of each exposure is extrapolated at constant velocity;
  // 1: the frame is held back by one, so start and end are interpolated with the next frame's pose.
  int latency_frames = 0;
  // Used for frames whose metadata has no exposure time (then flagged in the result). A typical
  // indoor auto-exposure at 30 fps.
  int64_t default_exposure_ns = 10'000'000;

  bool operator==(const MotionConfig&) const = default;
};

// Its keys, one row each: the name in the file, the member (whose initializer is the default), the
// rule the value must meet, and the help `arpipe config --defaults` prints (docs/ARCHITECTURE.md, "Adding a config key").
template <class V>
void visit(V& v, MotionConfig& s) {
  v.key("enabled", s.enabled, "runs only while tracking is on");
  // Only the previous-current (0) or current-next (1) segment is implemented; holding more frames
  // would add latency without a better estimate of one exposure.
  v.key("latency_frames", s.latency_frames,
        OneOfInts{{0, 1}, "0 (extrapolate, no delay) or 1 (hold each frame back by one and interpolate)"},
        "0: extrapolate at constant velocity; 1: hold a frame back and interpolate");
  // Up to one second: longer than any frame interval a tracking camera runs at. The stage caps it
  // at each frame's own interval, and frames with their own exposure never use it.
  v.key("default_exposure_ms", s.default_exposure_ns, MillisecondsAsNs{NumberRange::open_closed(0, 1000).in("ms")},
        "for frames without an exposure time; capped at the frame interval");
}

// One key of a kinematic body's pose track, relative to the physics' start (the first frame's
// exposure start): between keys the pose moves at constant velocity, before and after it holds.
struct PoseKey {
  double time_s = 0;
  Vec3 position_m{0, 0, 0};
  double yaw_rad = 0;

  bool operator==(const PoseKey&) const = default;
};

template <class V>
void visit(V& v, PoseKey& s) {
  v.key("time_s", s.time_s, NumberRange::closed(0, 1e6).in("s"), "since the physics started (the first frame)");
  v.key("position_m", s.position_m, NumberRange::closed(-1e4, 1e4).in("m"), "in the world (anchor) frame");
  v.key("yaw_deg", s.yaw_rad, Degrees{NumberRange::closed(-1e6, 1e6)}, "about world z");
}

// A virtual object as a rigid body (render/scene_physics.h, core/physics): it starts where the
// object is placed and moves on the frames' exposure timestamps.
struct ObjectPhysics {
  ObjectMotion kind = ObjectMotion::None;
  double mass_kg = 1.0;
  Vec3 velocity_mps{0, 0, 0};        // initial, world frame
  Vec3 spin_radps{0, 0, 0};          // initial angular velocity, world frame
  double restitution = 0.5;
  double friction = 0.5;
  double rolling_friction = 0;       // metres (a torque arm); 0: a ball rolls on for ever
  double linear_damping = 0;         // per second
  double angular_damping = 0;
  BodyShapeChoice shape = BodyShapeChoice::Auto;
  std::vector<PoseKey> track;        // kinematic bodies only

  bool operator==(const ObjectPhysics&) const = default;
};

template <class V>
void visit(V& v, ObjectPhysics& s) {
  v.key("kind", s.kind, kObjectMotionNames,
        "none: placed as configured; static; dynamic: gravity and contacts; kinematic: follows its track");
  v.key("mass_kg", s.mass_kg, NumberRange::closed(1e-6, 1e6).in("kg"), "dynamic bodies");
  v.key("velocity_mps", s.velocity_mps, NumberRange::closed(-1000, 1000).in("m/s"), "initial, world frame");
  v.key("spin_deg_s", s.spin_radps, Degrees{NumberRange::closed(-1e5, 1e5).in("degrees/s")},
        "initial angular velocity, world frame");
  v.key("restitution", s.restitution, NumberRange::closed(0, 1), "bounce: combined with the other surface's by product");
  v.key("friction", s.friction, NumberRange::closed(0, 10), "combined by product");
  v.key("rolling_friction", s.rolling_friction, NumberRange::closed(0, 10).in("m"), "0: a ball rolls on for ever");
  v.key("linear_damping", s.linear_damping, NumberRange::closed(0, 1).in("per second"), "air drag stand-in");
  v.key("angular_damping", s.angular_damping, NumberRange::closed(0, 1).in("per second"), "");
  v.key("shape", s.shape, kBodyShapeNames, "collision shape; auto: from a builtin mesh, else the convex hull");
  v.sections("track", s.track, "kinematic bodies: [[render.objects.physics.track]] pose keys, in time order");
}

struct SceneObject {
  std::string mesh = "builtin:cube";   // "builtin:cube", "builtin:pyramid", or a glTF 2.0 file
  Vec3 position_m{0, 0, 0};            // in the world (anchor) frame
  double yaw_rad = 0;                  // about world z
  double scale = 1.0;
  Vec3 color{0.8, 0.3, 0.1};           // linear base colour for builtin meshes
  // Its environment light (core/config/object_prt.h): SH irradiance at each normal, or the
  // precomputed radiance transfer baked per vertex ([render.prt]).
  ObjectPrt prt = ObjectPrt::Shadowed;
  // Weight of a glossy reflection of the environment (the 3-band radiance along the mirror
  // direction, added untinted), [0, 1]; 0: purely diffuse.
  double specular = 0;
  ObjectPhysics physics;

  bool operator==(const SceneObject&) const = default;
};

// Its keys, one row each: the name in the file, the member (whose initializer is the default), the
// rule the value must meet, and the help `arpipe config --defaults` prints (docs/ARCHITECTURE.md, "Adding a config key").
template <class V>
void visit(V& v, SceneObject& s) {
  v.key("mesh", s.mesh, NotEmpty{"\"builtin:cube\", \"builtin:pyramid\" or a glTF file"},
        "\"builtin:cube\", \"builtin:pyramid\" or a glTF 2.0 file");
  v.key("position_m", s.position_m, "in the world (anchor) frame");
  v.key("yaw_deg", s.yaw_rad, Degrees{}, "about world z");
  v.key("scale", s.scale, NumberRange::above(0), "size factor");
  v.key("color", s.color, NumberRange::at_least(0), "linear base colour of builtin meshes");
  v.key("prt", s.prt, kObjectPrtNames,
        "environment light: off (SH irradiance at each normal) or the baked transfer ([render.prt])");
  v.key("specular", s.specular, NumberRange::closed(0, 1), "glossy reflection of the environment, added untinted");
  v.section("physics", s.physics, "the object as a rigid body ([render.physics]); kind = \"none\": placed as configured");
}

// Real geometry re-created as an invisible "phantom" (seed 003): a mesh placed where a real object
// is, which hides the virtual objects behind it, catches their shadows, shadows them and stops
// them (core/config/proxy_roles.h). Placed like an object; R = Rz(yaw) Ry(pitch) Rx(roll).
struct SceneProxy {
  std::string name;                    // for messages and results; "" names it by its index
  std::string mesh = "builtin:box";    // a builtin or a glTF 2.0 file
  Vec3 size_m{0.1, 0.1, 0.1};          // builtin:box, builtin:cylinder (diameters x, y; height z), builtin:plane (x, y)
  Vec3 position_m{0, 0, 0};            // in the world (anchor) frame
  double yaw_rad = 0;
  double pitch_rad = 0;
  double roll_rad = 0;
  double scale = 1.0;
  ProxyRoles roles;
  ColliderChoice collider = ColliderChoice::Auto;
  std::string collision_mesh;          // a (simplified) glTF file for collisions; "": the mesh
  double restitution = 1.0;            // 1: the body's own restitution applies (combined by product)
  double friction = 1.0;
  // A panorama source's viewpoint this proxy stands in (source.panorama: 0 its own table, k the
  // k-th [[source.panorama.viewpoints]]); -1: every frame. Its collider, too, stops bodies only there.
  int viewpoint = -1;
  // A glTF mesh's parts (core/scene/gltf_animation.h). node: only that node and its subtree, in the
  // node's own frame, placed where the file's animation puts the node at each frame's time
  // (render/proxy_animator.h) and then by position/yaw/.../scale; "": the whole file.
  // skip_animated_nodes: the file without the nodes its animations move (the static rest of an
  // animated scene). animation: which of the file's animations ("": its first).
  std::string node;
  bool skip_animated_nodes = false;
  std::string animation;

  bool operator==(const SceneProxy&) const = default;
};

template <class V>
void visit(V& v, SceneProxy& s) {
  v.key("name", s.name, "for messages and results");
  v.key("mesh", s.mesh, NotEmpty{"a builtin (\"builtin:box\", \"builtin:cylinder\", ...) or a glTF file"},
        "a builtin (box, cylinder, plane, cube, sphere, ...) or a glTF 2.0 file");
  v.key("size_m", s.size_m, NumberRange::closed(0, 1e3).in("m"),
        "builtin:box x, y, z; builtin:cylinder diameters x, y and height z; builtin:plane x, y (each > 0 that the mesh uses)");
  v.key("position_m", s.position_m, NumberRange::closed(-1e4, 1e4).in("m"), "in the world (anchor) frame");
  v.key("yaw_deg", s.yaw_rad, Degrees{NumberRange::closed(-360, 360)}, "about world z");
  v.key("pitch_deg", s.pitch_rad, Degrees{NumberRange::closed(-360, 360)}, "about y, before the yaw");
  v.key("roll_deg", s.roll_rad, Degrees{NumberRange::closed(-360, 360)}, "about x, before the pitch");
  v.key("scale", s.scale, NumberRange::closed(1e-6, 1e6), "size factor");
  v.key("roles", s.roles, ProxyRoleNames{}, "any of \"occlude\", \"receive_shadows\", \"cast_shadows\", \"collide\"");
  v.key("collider", s.collider, kColliderNames, "auto: from a builtin mesh, else the triangles");
  v.key("collision_mesh", s.collision_mesh, "a (simplified) glTF file for collisions; \"\": the mesh");
  v.key("restitution", s.restitution, NumberRange::closed(0, 1), "1: the body's own applies");
  v.key("friction", s.friction, NumberRange::closed(0, 10), "1: the body's own applies");
  v.key("viewpoint", s.viewpoint, IntRange{-1, int(PanoramaConfig::kMaxViewpoints) - 1},
        "the panorama viewpoint it stands in (0: source.panorama's own); -1: every frame");
  v.key("node", s.node,
        "a glTF mesh's node: only its subtree, placed where the file's animation puts it at the frame's time; \"\": the whole file");
  v.key("skip_animated_nodes", s.skip_animated_nodes, "leave out the glTF nodes its animations move (the static rest)");
  v.key("animation", s.animation, "which of the glTF file's animations moves the node (\"\": its first)");
}

// The rigid-body world of render.objects[].physics and the "collide" proxies (core/physics).
struct PhysicsConfig {
  int substep_hz = 960;                      // fixed substeps per second (bench physics: 960 is within 1 %)
  Vec3 gravity_mps2{0, 0, -9.80665};         // world frame: z up off a table's tag
  bool ground = true;                        // the plane z = render.shadows.receiver_height_m collides
  int solver_iterations = 30;
  double floor_limit_z_m = -10;              // a body below this has left the world: removed, counted
  double world_radius_m = 1000;              // likewise beyond this distance from the origin
  int64_t max_advance_ns = 10'000'000'000;   // one frame simulates at most this much; a longer gap freezes
  int64_t history_ns = 500'000'000;          // kept for exposure and row poses

  bool operator==(const PhysicsConfig&) const = default;
};

template <class V>
void visit(V& v, PhysicsConfig& s) {
  v.key("substep_hz", s.substep_hz, IntRange{60, 10000}, "fixed substeps per second");
  v.key("gravity_mps2", s.gravity_mps2, NumberRange::closed(-1000, 1000).in("m/s^2"), "world frame (z up off the tag)");
  v.key("ground", s.ground, "the plane z = render.shadows.receiver_height_m collides");
  v.key("solver_iterations", s.solver_iterations, IntRange{1, 1000}, "per substep");
  v.key("floor_limit_z_m", s.floor_limit_z_m, NumberRange::closed(-1e6, 1e6).in("m"), "a body below it is removed");
  v.key("world_radius_m", s.world_radius_m, NumberRange::closed(1e-3, 1e7).in("m"), "a body beyond it is removed");
  v.key("max_advance_ms", s.max_advance_ns, MillisecondsAsNs{NumberRange::closed(1, 3.6e6).in("ms")},
        "simulated per frame at most; a longer gap freezes the world");
  v.key("history_ms", s.history_ns, MillisecondsAsNs{NumberRange::closed(1, 60000).in("ms")},
        "kept for exposure and row poses");
}

// Motion blur of the virtual layer (docs/ARCHITECTURE.md, "Motion blur"): how the virtual objects
// are smeared over each exposure to match the camera's own blur.
struct BlurConfig {
  BlurMethod method = BlurMethod::IntraframeWarp;  // core/config/blur_method.h
  // Samples per frame; 0 chooses them from the frame's image motion (intraframe-warp: the thesis's rule).
  int samples = 0;
  // Below this much image motion over the exposure a frame is drawn sharp, at no extra cost.
  double min_motion_px = 0.5;

  bool operator==(const BlurConfig&) const = default;
};

// Its keys, one row each: the name in the file, the member (whose initializer is the default), the
// rule the value must meet, and the help `arpipe config --defaults` prints (docs/ARCHITECTURE.md, "Adding a config key").
template <class V>
void visit(V& v, BlurConfig& s) {
  v.key("method", s.method, kBlurMethodNames,
        "accumulate: N renders (the reference); intraframe-warp: seed 000's 2 renders + affine warps; "
        "velocity: fastest");
  // 1024: far beyond what converges (bench blur's reference uses 256); intraframe-warp caps at 50.
  v.key("samples", s.samples, IntRange{0, 1024}, "0: from the frame's image motion");
  v.key("min_motion_px", s.min_motion_px, NumberRange::closed(0, 1000).in("pixels"),
        "frames with less image motion are drawn sharp");
}

// Shadows of the virtual objects on themselves and on the real ground (docs/ARCHITECTURE.md,
// "Light and shadows"): a shadow map from the directional light, filtered by `method`.
struct ShadowConfig {
  ShadowMethod method = ShadowMethod::Pcss;  // core/config/shadow_method.h
  int map_size = 1024;                   // texels across: 256, 512, 1024, 2048 or 4096
  int pcf_kernel = 3;                    // pcf: k x k taps, 1..16 (the seed: 3 real time, 8 for quality)
  int vsm_blur = 7;                      // vsm: Gaussian taps across, odd, 1..31 (the seed: 7)
  double vsm_bleed_reduction = 0.2;      // vsm: cuts the Chebyshev tail below this, [0, 0.95)
  double depth_bias_texels = 1.5;        // self-shadowing bias, in texels of the map's width
  double receiver_height_m = 0.0;        // world z of the real ground the shadows fall on
  // The size of the config's fixed light (render.light_direction), for pcss; probe and sun
  // estimates bring their own (0.53 degrees for the sun).
  double light_angular_diameter_deg = 2.0;
  // The virtual objects also hide part of the ambient light from the real surfaces beside them
  // (each as a sphere of its mean projected area); the catcher darkens those surfaces too. Off
  // by default: closer to the truth outdoors (bench shadows), but the ground catcher grows by
  // two of the spheres' radii, and the footprint with it.
  bool sky_occlusion = false;
  // The real ground's albedo, for the light it bounces onto tilted real surfaces (proxies that
  // catch shadows) under the config's constant ambient, which is a sky above the ground: a face
  // tilted by t from up sees the sky over (1 + cos t) / 2 of its view and the lit ground over the
  // rest. An estimated light's SH already holds what the ground sends.
  double ground_albedo = 0.2;
  // The ground catcher's ratio is a function of the ground point alone: while the light, the
  // shadow maps and the casters stay the same, it is baked once into a texture over the catcher
  // (render/shadow/catcher_bake.h) and each frame reads it back with one filtered lookup per pixel.
  bool bake_catcher = true;

  bool operator==(const ShadowConfig&) const = default;
};

// Its keys, one row each: the name in the file, the member (whose initializer is the default), the
// rule the value must meet, and the help `arpipe config --defaults` prints (docs/ARCHITECTURE.md, "Adding a config key").
template <class V>
void visit(V& v, ShadowConfig& s) {
  v.key("method", s.method, kShadowMethodNames,
        "hard: binary; pcf: k x k filter; pcss: penumbra from the light's size; vsm-packed: RGBA8 moments");
  v.key("map_size", s.map_size, OneOfInts{{256, 512, 1024, 2048, 4096}, ""}, "texels across");
  v.key("pcf_kernel", s.pcf_kernel, IntRange{1, 16}, "pcf: k x k taps");
  v.key("vsm_blur", s.vsm_blur, IntRange{1, 31}, "vsm: Gaussian taps across, odd");
  v.key("vsm_bleed_reduction", s.vsm_bleed_reduction, NumberRange::closed_open(0, 0.95), "vsm: cuts light bleeding");
  v.key("depth_bias_texels", s.depth_bias_texels, NumberRange::closed(0, 100).in("texels"), "self-shadowing bias");
  v.key("receiver_height_m", s.receiver_height_m, "world z of the real ground");
  v.key("light_angular_diameter_deg", s.light_angular_diameter_deg, NumberRange::closed_open(0, 90).in("degrees"),
        "size of the fixed light (pcss); estimates bring their own");
  v.key("sky_occlusion", s.sky_occlusion, "the objects also hide ambient light from the real surfaces beside them (costs footprint)");
  v.key("ground_albedo", s.ground_albedo, NumberRange::closed(0, 1),
        "the real ground's: the light it bounces onto tilted real surfaces that catch shadows, under a constant ambient");
  v.key("bake_catcher", s.bake_catcher,
        "bake the ground's shadow into a texture while light and casters stay still (false: filter it per pixel every frame)");
}

// The precomputed radiance transfer bake (render/prt): run once per mesh and kept in a cache
// keyed by the mesh's content.
struct PrtConfig {
  int samples = 32;                       // per axis of the stratified sphere samples (samples^2 rays)
  int bands = 3;                          // baked bands, 3..8 (the shader uses the first 3)
  std::filesystem::path cache_dir;        // empty: $XDG_CACHE_HOME/arpipe/prt or ~/.cache/arpipe/prt

  bool operator==(const PrtConfig&) const = default;
};

// Its keys, one row each: the name in the file, the member (whose initializer is the default), the
// rule the value must meet, and the help `arpipe config --defaults` prints (docs/ARCHITECTURE.md, "Adding a config key").
template <class V>
void visit(V& v, PrtConfig& s) {
  v.key("samples", s.samples, IntRange{2, 256}, "per axis: samples^2 directions per vertex");
  v.key("bands", s.bands, IntRange{3, 8}, "SH bands baked (the shader uses 3)");
  v.key("cache_dir", s.cache_dir, "\"\": $XDG_CACHE_HOME/arpipe/prt, else ~/.cache/arpipe/prt");
}

struct RenderConfig {
  bool enabled = true;
  std::vector<SceneObject> objects;  // none unless the config lists them
  std::vector<SceneProxy> proxies;   // real geometry as phantoms; none unless listed
  PhysicsConfig physics;
  Vec3 light_direction = normalized(Vec3{0.3, -0.4, 1.0});  // world frame, towards the light; unit length
  // 0: the light is infinitely far (a directional light); > 0: a lamp this far from the world
  // origin along light_direction (shadows fan out from it).
  double light_distance_m = 0;
  Vec3 light_color{1.0, 1.0, 1.0};       // linear
  Vec3 ambient{0.25, 0.25, 0.25};        // linear
  int msaa_samples = 4;
  EglPlatformRequest egl_platform = EglPlatformRequest::Auto;
  LensMode lens = LensMode::Map;
  // "map" only: canvas pixels per pinhole-core pixel, in [1, 4]. 4x multisampling alone leaves a
  // straight edge up to 1/8 canvas pixel off; a finer canvas divides that, at its square in fill
  // and memory (tests/render/lens_matched_rendering_test.cpp measures both).
  double lens_canvas_scale = 1.5;
  // With a rolling shutter (non-zero readout time and a motion estimate) draw each vertex with the
  // pose of its own row's exposure, so the virtual layer skews like the picture.
  bool rolling_shutter = true;
  // A predicted pose (track.max_predicted_frames) is drawn only while its stated uncertainty is at
  // most this many degrees: past it the object would stand visibly in the wrong place.
  double max_predicted_uncertainty_deg = 5.0;
  // Hand the last virtual layer on when the pose over the exposure, the light and the objects are
  // unchanged within render/layer_reuse.h's tolerances (a still camera over a still scene).
  bool reuse_layer = true;
  // Every pass over the whole image instead of the objects' footprint: the same picture at the
  // whole frame's cost, for checking the footprint (tests/render/footprint_test.cpp).
  bool full_canvas = false;
  // Proxies that only hide are drawn from the coarsest level of their mesh whose surface strays at
  // most this many canvas pixels from the full mesh's at the proxy's nearest point
  // (core/scene/occluder_levels.h); 0: always the full mesh.
  double occluder_lod_px = 0.1;
  BlurConfig blur;
  ShadowConfig shadows;
  PrtConfig prt;

  bool operator==(const RenderConfig&) const = default;
};

// Its keys, one row each: the name in the file, the member (whose initializer is the default), the
// rule the value must meet, and the help `arpipe config --defaults` prints (docs/ARCHITECTURE.md, "Adding a config key").
template <class V>
void visit(V& v, RenderConfig& s) {
  v.key("enabled", s.enabled, "draw the virtual objects");
  v.key("light_direction", s.light_direction, "world frame, towards the light; normalised on load");
  v.key("light_distance_m", s.light_distance_m, NumberRange::closed(0, 1e6).in("m; 0: infinitely far"),
        "0: infinitely far; > 0: a lamp that far along light_direction");
  v.key("light_color", s.light_color, NumberRange::at_least(0), "linear RGB");
  v.key("ambient", s.ambient, NumberRange::at_least(0), "linear RGB");
  v.key("msaa_samples", s.msaa_samples, OneOfInts{{0, 1, 2, 4}, ""}, "multisampling");
  v.key("egl_platform", s.egl_platform, kEglPlatformRequestNames,
        "EGL platform; auto: a device when the EGL device platform lists one, else surfaceless");
  v.key("lens", s.lens, kLensModeNames,
        "how the virtual layer matches the real lens: map: draw pinhole on an enlarged canvas, warp through a "
        "per-pixel map (any lens mrcal can unproject); vertex: distort per vertex (PINHOLE, OPENCV4/5/8); "
        "undistort: undistort the camera frame to the pinhole core and draw pinhole");
  // 4x multisampling alone leaves a straight edge up to 1/8 canvas pixel off; a finer canvas
  // divides that, at its square in fill and memory (tests/render/lens_matched_rendering_test.cpp).
  v.key("lens_canvas_scale", s.lens_canvas_scale, NumberRange::closed(1, 4),
        "\"map\": canvas pixels per core pixel; finer edges, cost grows with its square");
  v.key("rolling_shutter", s.rolling_shutter, "draw each row with its own exposure's pose when the readout time is non-zero");
  v.key("max_predicted_uncertainty_deg", s.max_predicted_uncertainty_deg, NumberRange::closed(0, 180).in("degrees"),
        "a predicted pose less certain than this is not drawn");
  v.key("reuse_layer", s.reuse_layer, "hand the last virtual layer on while pose, light and objects are unchanged");
  v.key("full_canvas", s.full_canvas, "every pass over the whole image, not the objects' footprint (for checking it)");
  v.key("occluder_lod_px", s.occluder_lod_px, NumberRange::closed(0, 10).in("pixels"),
        "proxies that only hide are drawn from a coarser mesh that strays at most this far; 0: the full mesh");
  v.section("blur", s.blur, "motion blur of the virtual layer over each exposure");
  v.section("shadows", s.shadows, "shadows of the virtual objects, on themselves and on the real ground");
  v.section("prt", s.prt, "precomputed radiance transfer, baked once per mesh (arpipe bake)");
  v.sections("objects", s.objects, "virtual objects: one [[render.objects]] each, placed in the world (anchor) frame; none when absent");
  v.section("physics", s.physics, "rigid bodies: objects with a physics kind, proxies that collide, the ground");
  v.sections("proxies", s.proxies, "real geometry as invisible phantoms: one [[render.proxies]] each; none when absent");
}

// A light probe sphere beside the anchor (core/light): where it is and what it is made of.
struct ProbeConfig {
  ProbeKind kind = ProbeKind::Mirror;
  Vec3 center_m{-0.15, 0.10, 0.04};      // world (anchor) frame
  double radius_m = 0.04;
  double reflectance = 0.9;              // mirror: specular reflectance; diffuse: albedo, (0, 1]
  ProbeMethod method = ProbeMethod::Auto;  // core/config/probe_method.h
  int max_lights = 1;                    // dominant lights kept, 1..4
  // 0: the lights are infinitely far; > 0: the strongest is a lamp this far from the probe's
  // centre (measured by hand: a probe sees directions only).
  double light_distance_m = 0;
  // A measurement within this of the last one handed on keeps that one (core/light/light_hold.h):
  // each light's direction seen from the probe (degrees), and the relative change of each light's
  // irradiance and of the ambient light. Both 0: every frame's measurement as it is.
  double hold_direction_deg = 0.5;
  double hold_change = 0.05;

  bool operator==(const ProbeConfig&) const = default;
};

// Its keys, one row each: the name in the file, the member (whose initializer is the default), the
// rule the value must meet, and the help `arpipe config --defaults` prints (docs/ARCHITECTURE.md, "Adding a config key").
template <class V>
void visit(V& v, ProbeConfig& s) {
  v.key("kind", s.kind, kProbeKindNames, "what the sphere is made of");
  v.key("center_m", s.center_m, "world frame");
  v.key("radius_m", s.radius_m, NumberRange::open_closed(0, 10).in("m"), "the sphere's radius");
  v.key("reflectance", s.reflectance, NumberRange::open_closed(0, 1), "mirror reflectance, or the diffuse sphere's albedo");
  v.key("method", s.method, kProbeMethodNames,
        "auto: environment for a mirror, fit for a diffuse sphere; brightest-image, brightest-sphere: "
        "seeds 001/004's brightest components");
  v.key("max_lights", s.max_lights, IntRange{1, 4}, "dominant lights kept");
  v.key("light_distance_m", s.light_distance_m, NumberRange::closed(0, 1e6).in("m; 0: infinitely far"),
        "0: lights infinitely far; > 0: the key lamp's distance from the probe");
  v.key("hold_direction_deg", s.hold_direction_deg, NumberRange::closed(0, 10).in("degrees"),
        "a measurement whose lights turned less than this (and changed less than hold_change) keeps the last light");
  v.key("hold_change", s.hold_change, NumberRange::closed(0, 1),
        "relative change of the lights' irradiance and the ambient light under which the last light is kept");
}

// The sun from place and time (core/light): NREL's SPA, turned into the anchor frame.
struct SunConfig {
  double latitude_deg = 0;               // [-90, 90], north positive
  double longitude_deg = 0;              // [-180, 180], east positive
  double altitude_m = 0;
  // "now": the system's UTC clock at each frame (live cameras); or an ISO 8601 instant for the
  // first frame, later frames adding their own time since it (replays).
  std::string time = "now";
  double heading_deg = 0;                // bearing of the anchor's +y axis from true north, clockwise
  double declination_deg = 0;            // added to heading_deg when it was read off a compass
  double pressure_mbar = 1013.25;        // for refraction
  double temperature_c = 15;
  // The sun's share of the light on the ground under a clear sky; the rest is sky. The ground
  // itself (light.ground_albedo) sets the overall level, measured per frame around the anchor.
  double direct_fraction = 0.85;

  bool operator==(const SunConfig&) const = default;
};

// Its keys, one row each: the name in the file, the member (whose initializer is the default), the
// rule the value must meet, and the help `arpipe config --defaults` prints (docs/ARCHITECTURE.md, "Adding a config key").
template <class V>
void visit(V& v, SunConfig& s) {
  v.key("latitude_deg", s.latitude_deg, NumberRange::closed(-90, 90).in("degrees, north positive"), "north positive");
  v.key("longitude_deg", s.longitude_deg, NumberRange::closed(-180, 180).in("degrees, east positive"), "east positive");
  v.key("altitude_m", s.altitude_m, NumberRange::closed(-500, 20000).in("m"), "above sea level");
  v.key("time", s.time, "\"now\" (system UTC clock) or an ISO 8601 instant for the first frame");
  v.key("heading_deg", s.heading_deg, NumberRange::closed(-360, 360).in("degrees"),
        "bearing of the anchor's +y axis from true north, clockwise");
  v.key("declination_deg", s.declination_deg, NumberRange::closed(-180, 180).in("degrees, east positive"),
        "magnetic declination, east positive, for a compass heading");
  v.key("pressure_mbar", s.pressure_mbar, NumberRange::open_closed(0, 5000).in("mbar"), "for refraction");
  v.key("temperature_c", s.temperature_c, NumberRange::open_closed(-273, 6000).in("degrees Celsius"), "for refraction");
  v.key("direct_fraction", s.direct_fraction, NumberRange::closed(0, 1), "the sun's share of the light on the ground");
}

// A light probe image file as the whole light (static): an HDR panorama of the place, projected
// onto spherical harmonics once at configure.
struct EnvironmentConfig {
  std::filesystem::path file;            // Radiance .hdr or OpenEXR .exr
  EnvironmentLayout layout = EnvironmentLayout::Equirectangular;
  double yaw_rad = 0;                    // turn of the probe about world z (probe up = world +z)
  double scale = 1;                      // radiance units of the file -> scene-linear units
  ShWindow window = ShWindow::None;      // against ringing

  bool operator==(const EnvironmentConfig&) const = default;
};

// Its keys, one row each: the name in the file, the member (whose initializer is the default), the
// rule the value must meet, and the help `arpipe config --defaults` prints (docs/ARCHITECTURE.md, "Adding a config key").
template <class V>
void visit(V& v, EnvironmentConfig& s) {
  v.key("file", s.file, "Radiance .hdr or OpenEXR .exr; required with source = \"environment\"");
  v.key("layout", s.layout, kEnvironmentLayoutNames, "the file's projection");
  v.key("yaw_deg", s.yaw_rad, Degrees{}, "turn of the probe about world z (probe up = world z)");
  v.key("scale", s.scale, NumberRange::open_closed(0, 1e12), "the file's radiance units to scene-linear units");
  v.key("window", s.window, kShWindowNames, "SH windowing against ringing");
}

// The panorama source's image as the light (seed 003's suggested image-based lighting): its
// radiance on 3 SH bands, per video frame, plus render.light_* as the one shadow-casting light.
struct PanoramaLightConfig {
  bool direct_light_from_render = true;  // false: the panorama's SH alone (no direct light, no shadows)
  ShWindow window = ShWindow::None;
  // The scene's exported lights (a glTF with KHR_lights_punctual) as the direct lights instead of
  // render.light_*; the brightest casts the shadows. lights_scale turns the file's photometric
  // units (lux; candela over the squared distance to the world origin) into the render's irradiance.
  std::filesystem::path lights_file;
  double lights_scale = 1;
  // Which of lights_file's animations moves its lights' nodes ("": its first), sampled at each
  // frame's time in the panorama's video (FrameMetadata::source_frame_time_ns).
  std::string lights_animation;

  bool operator==(const PanoramaLightConfig&) const = default;
};

template <class V>
void visit(V& v, PanoramaLightConfig& s) {
  v.key("direct_light_from_render", s.direct_light_from_render,
        "render.light_direction and light_color as the shadow-casting light; false: the panorama alone (no shadows)");
  v.key("window", s.window, kShWindowNames, "SH windowing against ringing");
  v.key("lights_file", s.lights_file,
        "a glTF whose KHR_lights_punctual lights are the direct lights instead of render.light_* (the brightest casts shadows)");
  v.key("lights_scale", s.lights_scale, NumberRange::open_closed(0, 1e12),
        "lights_file's lux (directional; candela / distance^2 from the world origin for point and spot) to irradiance");
  v.key("lights_animation", s.lights_animation,
        "which of lights_file's animations moves its lights, at the video frame's time (\"\": its first)");
}

// The light stage: where the light comes from.
struct LightConfig {
  LightSource source = LightSource::Fixed;  // core/config/light_source.h
  CameraResponse response;               // sRGB
  double smoothing_s = 0.3;              // time constant of the temporal smoothing, [0, 60]
  // The real ground around the anchor, whose brightness gives the light's strength where nothing
  // else can: the sun always, and a probe whose brightest light is clipped.
  Vec3 ground_albedo{0.3, 0.3, 0.3};
  ProbeConfig probe;
  SunConfig sun;
  EnvironmentConfig environment;
  PanoramaLightConfig panorama;

  bool operator==(const LightConfig&) const = default;
};

// Its keys, one row each: the name in the file, the member (whose initializer is the default), the
// rule the value must meet, and the help `arpipe config --defaults` prints (docs/ARCHITECTURE.md, "Adding a config key").
template <class V>
void visit(V& v, LightConfig& s) {
  v.key("source", s.source, kLightSourceNames,
        "fixed: render.light_*; probe: a probe sphere in view; sun: place and time; environment: an HDR probe file; "
        "panorama: the panorama source's image");
  v.key("response", s.response, CameraResponseName{}, "the camera's response curve");
  v.key("smoothing_s", s.smoothing_s, NumberRange::closed(0, 60).in("s"), "time constant of the temporal smoothing");
  v.key("ground_albedo", s.ground_albedo, NumberRange::open_closed(0, 1),
        "of the real ground, whose brightness sets the sun's level and a clipped lamp's");
  v.section("probe", s.probe, "a light probe sphere beside the anchor");
  v.section("sun", s.sun, "the sun from place and time (NREL SPA)");
  v.section("environment", s.environment, "an HDR light probe file as the whole light");
  v.section("panorama", s.panorama, "the panorama source's image as the light");
}

struct PngSinkConfig {
  bool enabled = false;  // on when the config has its table ([sinks.*] below)
  std::filesystem::path dir = "out/png";
  int every = 1;  // write every Nth frame
  int compression = 1;  // OpenCV's own default level (capture/sinks/png_sink.cpp)

  bool operator==(const PngSinkConfig&) const = default;
};

// Its keys, one row each: the name in the file, the member (whose initializer is the default), the
// rule the value must meet, and the help `arpipe config --defaults` prints (docs/ARCHITECTURE.md, "Adding a config key").
template <class V>
void visit(V& v, PngSinkConfig& s) {
  v.key("enabled", s.enabled, "write PNG frames");
  v.key("dir", s.dir, "the directory the frames go to");
  v.key("every", s.every, IntRange{1}, "write every Nth frame");
  v.key("compression", s.compression, IntRange{0, 9}, "zlib level; 1: OpenCV's fast default (SUB filter, RLE); other levels use zlib's default strategy, "
        "not always smaller on camera noise");
}
struct Y4mSinkConfig {
  bool enabled = false;  // on when the config has its table ([sinks.*] below)
  std::filesystem::path path = "out/arpiped.y4m";

  bool operator==(const Y4mSinkConfig&) const = default;
};

// Its keys, one row each: the name in the file, the member (whose initializer is the default), the
// rule the value must meet, and the help `arpipe config --defaults` prints (docs/ARCHITECTURE.md, "Adding a config key").
template <class V>
void visit(V& v, Y4mSinkConfig& s) {
  v.key("enabled", s.enabled, "write a Y4M video");
  v.key("path", s.path, "the video file");
}
struct RecordingSinkConfig {
  bool enabled = false;  // on when the config has its table ([sinks.*] below)
  std::filesystem::path path = "out/composited";

  bool operator==(const RecordingSinkConfig&) const = default;
};

// Its keys, one row each: the name in the file, the member (whose initializer is the default), the
// rule the value must meet, and the help `arpipe config --defaults` prints (docs/ARCHITECTURE.md, "Adding a config key").
template <class V>
void visit(V& v, RecordingSinkConfig& s) {
  v.key("enabled", s.enabled, "write a recording (replayable)");
  v.key("path", s.path, "the recording directory");
}
struct ResultsSinkConfig {
  bool enabled = false;  // on when the config has its table ([sinks.*] below)
  std::filesystem::path path = "out/results.jsonl";  // per-frame pose, tracking state, timings

  bool operator==(const ResultsSinkConfig&) const = default;
};

// Its keys, one row each: the name in the file, the member (whose initializer is the default), the
// rule the value must meet, and the help `arpipe config --defaults` prints (docs/ARCHITECTURE.md, "Adding a config key").
template <class V>
void visit(V& v, ResultsSinkConfig& s) {
  v.key("enabled", s.enabled, "write per-frame results");
  v.key("path", s.path, "per-frame pose, tracking state and timings as JSON lines");
}

// The live HTTP outputs (capture/sinks/http): the preview page, MJPEG, snapshots, state, metrics.
struct HttpSinkConfig {
  bool enabled = false;  // on when the config has its table ([sinks.*] below)
  // "HOST:PORT" (IPv4 or [IPv6]), a Unix socket path (starting with "/" or "./"), or "systemd":
  // the socket systemd passes (socket activation, systemd/arpiped-http.socket).
  std::string listen = "127.0.0.1:8080";
  int jpeg_quality = 85;
  int max_clients = 16;
  int client_timeout_ms = 10'000;
  int camera_away_ms = 2'000;

  bool operator==(const HttpSinkConfig&) const = default;
};

// Its keys, one row each: the name in the file, the member (whose initializer is the default), the
// rule the value must meet, and the help `arpipe config --defaults` prints (docs/ARCHITECTURE.md, "Adding a config key").
template <class V>
void visit(V& v, HttpSinkConfig& s) {
  v.key("enabled", s.enabled, "serve the live preview, MJPEG, snapshots, state and metrics over HTTP");
  v.key("listen", s.listen, "\"HOST:PORT\" (loopback by default), a Unix socket path (\"/...\"), or \"systemd\" (socket activation)");
  v.key("jpeg_quality", s.jpeg_quality, IntRange{1, 100}, "MJPEG and snapshot quality (libjpeg-turbo)");
  v.key("max_clients", s.max_clients, IntRange{1, 1024}, "connections at once; more are refused");
  v.key("client_timeout_ms", s.client_timeout_ms, IntRange{100, 3'600'000}, "a client that sends or takes nothing for this long is dropped");
  v.key("camera_away_ms", s.camera_away_ms, IntRange{100, 600'000}, "no frame for this long: the stream shows a placeholder that says so");
}

// A V4L2 output device (a v4l2loopback node) that browsers, OBS or video calls open as a camera.
struct V4l2SinkConfig {
  bool enabled = false;  // on when the config has its table ([sinks.*] below)
  std::filesystem::path device = "/dev/video10";
  V4l2OutputFormat format = V4l2OutputFormat::Yuyv;

  bool operator==(const V4l2SinkConfig&) const = default;
};

// Its keys, one row each: the name in the file, the member (whose initializer is the default), the
// rule the value must meet, and the help `arpipe config --defaults` prints (docs/ARCHITECTURE.md, "Adding a config key").
template <class V>
void visit(V& v, V4l2SinkConfig& s) {
  v.key("enabled", s.enabled, "write the composite to a V4L2 output device (v4l2loopback), a camera to other programs");
  v.key("device", s.device, "the output device node");
  v.key("format", s.format, kV4l2OutputFormatNames, "pixel format written: yuyv (what most readers take), rgb24 (exact)");
}

// A GStreamer pipeline fed through its appsrc: a file, an RTSP server, a hardware encoder.
struct GstreamerSinkConfig {
  bool enabled = false;  // on when the config has its table ([sinks.*] below)
  std::string pipeline = "appsrc name=arpipe ! videoconvert ! x264enc tune=zerolatency speed-preset=ultrafast ! mp4mux ! filesink location=out/arpiped.mp4";
  int eos_timeout_ms = 5'000;
  int restart_ms = 0;  // 0: a failed pipeline stays stopped

  bool operator==(const GstreamerSinkConfig&) const = default;
};

// Its keys, one row each: the name in the file, the member (whose initializer is the default), the
// rule the value must meet, and the help `arpipe config --defaults` prints (docs/ARCHITECTURE.md, "Adding a config key").
template <class V>
void visit(V& v, GstreamerSinkConfig& s) {
  v.key("enabled", s.enabled, "feed the composite to a GStreamer pipeline");
  v.key("pipeline", s.pipeline, "gst-launch syntax, starting with \"appsrc name=arpipe\" (RGB frames, timestamps from the exposures)");
  v.key("eos_timeout_ms", s.eos_timeout_ms, IntRange{0, 600'000},
        "how long the pipeline may take to finish its file at the end, and to take a frame before it is left out");
  v.key("restart_ms", s.restart_ms, IntRange{0, 3'600'000},
        "after a pipeline error, build it again this often until it runs (for network outputs: a file would be started "
        "again); 0: stay stopped");
}

struct SinksConfig {
  PngSinkConfig png;
  Y4mSinkConfig y4m;
  RecordingSinkConfig recording;
  ResultsSinkConfig results;
  HttpSinkConfig http;
  V4l2SinkConfig v4l2;
  GstreamerSinkConfig gstreamer;

  bool operator==(const SinksConfig&) const = default;
};

// Its keys, one row each: the name in the file, the member (whose initializer is the default), the
// rule the value must meet, and the help `arpipe config --defaults` prints (docs/ARCHITECTURE.md, "Adding a config key").
template <class V>
// A sink writes only when the config names it: its table present turns it on (unless it says
// enabled = false), absent leaves it off.
void visit(V& v, SinksConfig& s) {
  v.switched_section("png", s.png, "composited frames as PNG files");
  v.switched_section("y4m", s.y4m, "composited frames as a Y4M video");
  v.switched_section("recording", s.recording, "composited frames as a recording");
  v.switched_section("results", s.results, "per-frame pose, tracking state and timings as JSON lines");
  v.switched_section("http", s.http, "live outputs over HTTP: preview page, MJPEG, snapshots, state, Prometheus metrics");
  v.switched_section("v4l2", s.v4l2, "the composite on a V4L2 output device (v4l2loopback): a camera for other programs");
  v.switched_section("gstreamer", s.gstreamer, "the composite into a GStreamer pipeline (files, RTSP, hardware encoders)");
}

struct PipelineConfig {
  int queue_depth = 4;
  int sink_queue_depth = 4;
  int64_t max_frames = 0;  // 0 = no limit
  log::Level log_level = log::Level::Info;
  // The first stage (tracking) of a frame runs on a helper thread while the later stages finish
  // the frame before, when the next frame is already waiting (a replay, a camera the pipeline
  // lags behind); each stage still sees every frame in order, so a replay stays the same frame for
  // frame. On by default: with the render stage's footprint and reuse it pays on two cores too,
  // 4-28 % more frames/s on the default, sun-outdoor and probe-indoor captures (BENCHMARKS.md
  // "Pipeline throughput"); a pipeline that keeps up with its camera never has a frame waiting,
  // so it changes nothing there.
  bool overlap_first_stage = true;

  bool operator==(const PipelineConfig&) const = default;
};

// Its keys, one row each: the name in the file, the member (whose initializer is the default), the
// rule the value must meet, and the help `arpipe config --defaults` prints (docs/ARCHITECTURE.md, "Adding a config key").
template <class V>
void visit(V& v, PipelineConfig& s) {
  v.key("queue_depth", s.queue_depth, IntRange{1}, "frames between threads");
  v.key("sink_queue_depth", s.sink_queue_depth, IntRange{1, 1024},
        "frames waiting for each sink; beyond it a live camera's slow sink drops its oldest (a replay waits)");
  v.key("max_frames", s.max_frames, IntRange{0}, "stop after this many frames; 0 = no limit");
  v.key("log_level", s.log_level, kLogLevelNames, "what the daemon logs");
  v.key("overlap_first_stage", s.overlap_first_stage,
        "track the next waiting frame (and convert its camera picture) on a helper thread while the last one renders");
}

// The daemon's control socket (arpipe ctl: status, reload, set, snapshot, record).
struct ControlConfig {
  // "": $RUNTIME_DIRECTORY/control.sock when systemd gives the service a runtime directory
  // (RuntimeDirectory=arpipe: /run/arpipe/control.sock), else none; "off": none; else its path.
  std::string socket;

  bool operator==(const ControlConfig&) const = default;
};

// Its keys, one row each: the name in the file, the member (whose initializer is the default), the
// rule the value must meet, and the help `arpipe config --defaults` prints (docs/ARCHITECTURE.md, "Adding a config key").
template <class V>
void visit(V& v, ControlConfig& s) {
  v.key("socket", s.socket, "Unix socket for arpipe ctl; \"\": $RUNTIME_DIRECTORY/control.sock under systemd, else none; \"off\": none");
}

struct Config {
  std::filesystem::path file;  // where it came from, for messages
  SourceConfig source;
  TrackConfig track;
  MotionConfig motion;
  LightConfig light;
  RenderConfig render;
  SinksConfig sinks;
  PipelineConfig pipeline;
  ControlConfig control;

  bool operator==(const Config&) const = default;
};

// Its keys, one row each: the name in the file, the member (whose initializer is the default), the
// rule the value must meet, and the help `arpipe config --defaults` prints (docs/ARCHITECTURE.md, "Adding a config key").
template <class V>
void visit(V& v, Config& s) {
  v.section("source", s.source, "the camera");
  v.section("track", s.track, "the anchor's tags and the camera's pose");
  v.section("motion", s.motion, "the camera's poses over each exposure (needs tracking)");
  v.section("light", s.light, "where the light comes from");
  v.section("render", s.render, "the virtual layer");
  v.section("sinks", s.sinks, "where the composited frames and results go");
  v.section("pipeline", s.pipeline, "threads and limits");
  v.section("control", s.control, "the daemon's control socket (arpipe ctl)");
}

// The config's file for messages, or "config" when it was not read from one.
inline std::string config_source_name(const Config& config) {
  return config.file.empty() ? std::string("config") : config.file.string();
}

// Loads a config file. Throws ConfigError naming the file and the place on any problem:
// unreadable file, TOML syntax, unknown key, wrong type, value out of range.
// overrides: "section.key=value" assignments (value in TOML syntax; a bare word such as fast or
// out/run1 is taken as a string) from the command line, applied before validation, so they are
// checked like the file. Elements of arrays of tables are addressed by index: render.objects.0.scale=2.
Config load_config(const std::filesystem::path& path, const std::vector<std::string>& overrides = {});
// Parses TOML text; source_name is used in messages.
Config parse_config(const std::string& text, const std::string& source_name,
                    const std::vector<std::string>& overrides = {});
// The config with every key at its default, as TOML text (what `arpipe config --defaults` prints).
std::string default_config_toml();

}  // namespace arpipe
