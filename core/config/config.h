// The daemon's configuration: a TOML file where every key has a default and unknown keys are errors.
// Degrees appear only here, at the boundary; the structs hold radians and metres.
#pragma once

#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/geometry/vec.h"

namespace arpipe {

// Bad config input; what() names the file, the line and column where known, and what was expected.
class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct SourceConfig {
  std::string type = "replay";          // "replay", "v4l2" or "libcamera"
  std::filesystem::path path;           // replay: the recording directory
  std::string pacing = "timestamps";    // replay: "timestamps" (real time) or "fast"
  bool loop = false;                    // replay: start again at the end (soak tests)
  int64_t timestamp_offset_ns = 0;      // added to every exposure_start_ns of this camera
  std::filesystem::path camera_model;   // overrides the recording's camera model; live: required to track

  // Live cameras (v4l2, libcamera). 0 or "auto": whatever the camera offers first.
  std::string device;                   // v4l2: /dev/videoN or a /dev/v4l/by-id|by-path link
  std::string camera;                   // libcamera: camera id, or its index in the list ("" = first)
  std::string role = "video";           // libcamera stream role: video, viewfinder, still, raw
  int width = 0;
  int height = 0;
  double fps = 0;
  std::string pixel_format = "auto";    // YUYV, NV12, RGB24, GREY, MJPG (v4l2: decoded to RGB24), auto
  int buffers = 4;                      // capture buffers (at least 4)
  int64_t exposure_us = 0;              // manual exposure; 0: auto exposure
  double gain = 0;                      // manual analogue gain (1 = unity); 0: auto
  double gain_unity = 100;              // v4l2: the gain control's value that means gain 1
  // v4l2: what the buffer timestamps mean when the driver does not say (no TSTAMP_SRC flag), or
  // "auto" to take the driver's flag (end-of-frame when it gives none).
  std::string timestamp_meaning = "auto";  // auto, start-of-exposure, end-of-frame
  int64_t readout_ns = 0;               // rolling-shutter readout (first to last row); 0: global
  int64_t frame_timeout_ms = 1000;      // a frame later than this is a timeout (counted)
  int64_t reconnect_min_ms = 100;       // first retry after a camera disappeared
  int64_t reconnect_max_ms = 5000;      // retries back off up to this

  bool operator==(const SourceConfig&) const = default;
};

// One tag of the anchor bundle: where its centre sits in the world (anchor) frame and how it is turned.
struct BundleTag {
  int id = 0;
  double size_m = 0.1;      // edge between the black and white borders (AprilTag's "tag size")
  Vec3 center_m{0, 0, 0};   // tag centre in the world frame
  double yaw_rad = 0;       // rotation about world z of the tag's x axis; tags lie in the z=0 plane

  bool operator==(const BundleTag&) const = default;
};

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

  bool operator==(const TrackConfig&) const = default;
};

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

struct SceneObject {
  std::string mesh = "builtin:cube";   // "builtin:cube", "builtin:pyramid", or a glTF 2.0 file
  Vec3 position_m{0, 0, 0};            // in the world (anchor) frame
  double yaw_rad = 0;                  // about world z
  double scale = 1.0;
  Vec3 color{0.8, 0.3, 0.1};           // linear base colour for builtin meshes
  // Its environment light: "off" (SH irradiance at each pixel's normal, no self-shadowing), or the
  // precomputed radiance transfer baked per vertex ([render.prt]): "unshadowed", "shadowed"
  // (self-shadowing) or "interreflected" (plus one grey bounce).
  std::string prt = "shadowed";
  // Weight of a glossy reflection of the environment (the 3-band radiance along the mirror
  // direction, added untinted), [0, 1]; 0: purely diffuse.
  double specular = 0;

  bool operator==(const SceneObject&) const = default;
};

// Motion blur of the virtual layer (docs/ARCHITECTURE.md, "Motion blur"): how the virtual objects
// are smeared over each exposure to match the camera's own blur.
struct BlurConfig {
  // "off"; "accumulate": full renders spread over the exposure, averaged (the reference);
  // "seed": seed 000, two renders at 1/4 and 3/4 plus affine-warped samples between them;
  // "velocity": one render plus a per-pixel velocity gather (fastest).
  std::string method = "seed";
  // Samples per frame; 0 chooses them from the frame's image motion (seed: the thesis's rule).
  int samples = 0;
  // Below this much image motion over the exposure a frame is drawn sharp, at no extra cost.
  double min_motion_px = 0.5;

  bool operator==(const BlurConfig&) const = default;
};

// Shadows of the virtual objects on themselves and on the real ground (docs/ARCHITECTURE.md,
// "Light and shadows"): a shadow map from the directional light, filtered by `method`.
struct ShadowConfig {
  // "off", "hard" (the seed's binary test), "pcf" (k x k percentage-closer filter), "pcss"
  // (penumbra from the light's angular size), "vsm" (variance shadow map, float moments), or
  // "vsm-packed" (the seed's 16-bit moments packed in RGBA8, for GLES 2-class hardware).
  std::string method = "pcss";
  int map_size = 1024;                   // texels across: 256, 512, 1024, 2048 or 4096
  int pcf_kernel = 3;                    // pcf: k x k taps, 1..16 (the seed: 3 real time, 8 for quality)
  int vsm_blur = 7;                      // vsm: Gaussian taps across, odd, 1..31 (the seed: 7)
  double vsm_bleed_reduction = 0.2;      // vsm: cuts the Chebyshev tail below this, [0, 0.95)
  double depth_bias_texels = 1.5;        // self-shadowing bias, in texels of the map's width
  double receiver_height_m = 0.0;        // world z of the real ground the shadows fall on
  // The size of the config's fixed light (render.light_direction), for pcss; probe and sun
  // estimates bring their own (0.53 degrees for the sun).
  double light_angular_diameter_deg = 2.0;

  bool operator==(const ShadowConfig&) const = default;
};

// The precomputed radiance transfer bake (render/prt): run once per mesh and kept in a cache
// keyed by the mesh's content.
struct PrtConfig {
  int samples = 32;                       // per axis of the stratified sphere samples (samples^2 rays)
  int bands = 3;                          // baked bands, 3..8 (the shader uses the first 3)
  std::filesystem::path cache_dir;        // empty: $XDG_CACHE_HOME/arpipe/prt or ~/.cache/arpipe/prt

  bool operator==(const PrtConfig&) const = default;
};

struct RenderConfig {
  bool enabled = true;
  std::vector<SceneObject> objects{SceneObject{}};
  Vec3 light_direction = normalized(Vec3{0.3, -0.4, 1.0});  // world frame, towards the light; unit length
  // 0: the light is infinitely far (a directional light); > 0: a lamp this far from the world
  // origin along light_direction (shadows fan out from it).
  double light_distance_m = 0;
  Vec3 light_color{1.0, 1.0, 1.0};       // linear
  Vec3 ambient{0.25, 0.25, 0.25};        // linear
  int msaa_samples = 4;
  std::string egl_platform = "auto";     // "auto", "surfaceless", "device"
  // How the virtual layer matches the real lens (docs/ARCHITECTURE.md, "Lens-matched rendering"):
  // "map": draw with the lens model's pinhole core on an enlarged canvas, then warp it through a
  //   per-pixel map built once with mrcal (any lens mrcal can unproject, up to 75 degrees off axis);
  // "vertex": distort per vertex in the vertex shader (PINHOLE and OPENCV4/5/8 only; edges between
  //   vertices stay straight);
  // "undistort": warp the camera frame to the pinhole core and draw pinhole: the output is an
  //   undistorted picture, whose camera model is the pinhole core.
  std::string lens = "map";
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
  BlurConfig blur;
  ShadowConfig shadows;
  PrtConfig prt;

  bool operator==(const RenderConfig&) const = default;
};

// A light probe sphere beside the anchor (core/light): where it is and what it is made of.
struct ProbeConfig {
  std::string kind = "mirror";           // "mirror" or "diffuse"
  Vec3 center_m{-0.15, 0.10, 0.04};      // world (anchor) frame
  double radius_m = 0.04;
  double reflectance = 0.9;              // mirror: specular reflectance; diffuse: albedo, (0, 1]
  // "auto" (environment for a mirror, fit for a diffuse sphere), "environment", "fit",
  // "seed-image" or "seed-sphere" (the seed's brightest-component method, image or sphere domain).
  std::string method = "auto";
  int max_lights = 1;                    // dominant lights kept, 1..4
  // 0: the lights are infinitely far; > 0: the strongest is a lamp this far from the probe's
  // centre (measured by hand: a probe sees directions only).
  double light_distance_m = 0;

  bool operator==(const ProbeConfig&) const = default;
};

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

// A light probe image file as the whole light (static): an HDR panorama of the place, projected
// onto spherical harmonics once at configure.
struct EnvironmentConfig {
  std::filesystem::path file;            // Radiance .hdr or OpenEXR .exr
  std::string layout = "equirect";       // "angular", "mirror-ball", "equirect" or "cube-cross"
  double yaw_rad = 0;                    // turn of the probe about world z (probe up = world +z)
  double scale = 1;                      // radiance units of the file -> scene-linear units
  std::string window = "none";           // "none", "hanning" or "lanczos": against ringing

  bool operator==(const EnvironmentConfig&) const = default;
};

// The light stage: where the light comes from.
struct LightConfig {
  // "fixed": render.light_direction, light_color and ambient (display-referred, no estimation);
  // "probe": a light probe sphere in view ([light.probe]); "sun": place and time ([light.sun]);
  // "environment": an HDR light probe file ([light.environment]).
  std::string source = "fixed";
  std::string response = "srgb";         // the camera's response curve: "srgb", "linear" or "gamma:<g>"
  double smoothing_s = 0.3;              // time constant of the temporal smoothing, [0, 60]
  // The real ground around the anchor, whose brightness gives the light's strength where nothing
  // else can: the sun always, and a probe whose brightest light is clipped.
  Vec3 ground_albedo{0.3, 0.3, 0.3};
  ProbeConfig probe;
  SunConfig sun;
  EnvironmentConfig environment;

  bool operator==(const LightConfig&) const = default;
};

struct PngSinkConfig {
  bool enabled = true;
  std::filesystem::path dir = "out/png";
  int every = 1;  // write every Nth frame

  bool operator==(const PngSinkConfig&) const = default;
};
struct Y4mSinkConfig {
  bool enabled = true;
  std::filesystem::path path = "out/arpiped.y4m";

  bool operator==(const Y4mSinkConfig&) const = default;
};
struct RecordingSinkConfig {
  bool enabled = false;
  std::filesystem::path path = "out/composited";

  bool operator==(const RecordingSinkConfig&) const = default;
};
struct ResultsSinkConfig {
  bool enabled = true;
  std::filesystem::path path = "out/results.jsonl";  // per-frame pose, tracking state, timings

  bool operator==(const ResultsSinkConfig&) const = default;
};

struct SinksConfig {
  PngSinkConfig png;
  Y4mSinkConfig y4m;
  RecordingSinkConfig recording;
  ResultsSinkConfig results;

  bool operator==(const SinksConfig&) const = default;
};

struct PipelineConfig {
  int queue_depth = 4;
  int64_t max_frames = 0;  // 0 = no limit
  std::string log_level = "info";

  bool operator==(const PipelineConfig&) const = default;
};

struct Config {
  std::filesystem::path file;  // where it came from, for messages
  SourceConfig source;
  TrackConfig track;
  MotionConfig motion;
  LightConfig light;
  RenderConfig render;
  SinksConfig sinks;
  PipelineConfig pipeline;

  bool operator==(const Config&) const = default;
};

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
