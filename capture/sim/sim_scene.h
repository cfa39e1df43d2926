// The simulator's scene: what the virtual camera looks at, how it moves and what its sensor does,
// as loaded from a configs/sim/*.toml file (sim_scene_loader.h). Plain data, already validated.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/config/choice_names.h"
#include "core/frame.h"
#include "core/geometry/camera_model.h"
#include "core/geometry/se3.h"
#include "core/image/camera_response.h"
#include "core/pixel_format.h"

namespace arpipe::sim {

using Rgb = std::array<double, 3>;  // linear RGB

// What covers a plane. The plane's local frame: x right, y up (the printed top), z out of the
// visible face; texture coordinates u = x / width + 1/2 (left to right), v = 1/2 - y / height
// (top to bottom), so texel row 0 is the printed top edge.
struct SimTexture {
  enum class Kind { None, AprilTag, Chessboard, Image };
  Kind kind = Kind::None;
  // AprilTag: the family's own bit pattern (apriltag_to_image), white border included. The plane
  // is sized by the loader so that the black border's edge measures the tag size.
  std::string family;
  int tag_id = 0;
  // Chessboard: rows x cols squares; the top-left square is dark. The plane is exactly the board
  // (the loader adds `margin_squares` of light paper around it).
  int rows = 0;
  int cols = 0;
  double margin_squares = 0;
  // Image: an 8-bit sRGB PNG/JPEG, decoded to linear reflectance (times `albedo`).
  std::filesystem::path image_path;
  // Two-tone textures: linear reflectance of the ink and of the paper.
  Rgb dark{0.03, 0.03, 0.03};
  Rgb light{0.80, 0.80, 0.80};
};
// texture.kind in a scene file (None: no [object.texture] table).
inline constexpr ChoiceName<SimTexture::Kind> kSimTextureKindNames[] = {{"apriltag", SimTexture::Kind::AprilTag},
                                                                        {"chessboard", SimTexture::Kind::Chessboard},
                                                                        {"image", SimTexture::Kind::Image}};

struct SimMaterial {
  enum class Kind { Lambertian, Mirror };
  Kind kind = Kind::Lambertian;
  Rgb albedo{0.5, 0.5, 0.5};  // Lambertian: diffuse reflectance; Mirror: specular reflectance
  SimTexture texture;         // Lambertian only; when set it replaces albedo (Image: multiplies)
  // Lambertian only: a glossy (Blinn-Phong) highlight of the lights on top of the diffuse term,
  // BRDF specular * (shininess + 8) / (8 pi) * (n.h)^shininess, h the half vector of the light
  // and view directions; it takes the light's colour (a dielectric such as paper or plastic).
  // 0: none (the pure Lambertian surface, bit for bit).
  double specular = 0;
  double shininess = 50;
};
inline constexpr ChoiceName<SimMaterial::Kind> kSimMaterialKindNames[] = {{"lambertian", SimMaterial::Kind::Lambertian},
                                                                          {"mirror", SimMaterial::Kind::Mirror}};

// A key of an object's pose track: where the object's frame sits at this time.
struct SimPoseKey {
  double time_s = 0;  // trajectory time (since the first frame's exposure start); >= 0, strictly increasing
  SE3 T_world_object;
};

struct SimObject {
  enum class Shape { Plane, Sphere, Mesh };
  std::string name;  // unique within the scene, as written in the scene file
  Shape shape = Shape::Plane;
  SE3 T_world_object;          // where the object's local frame sits in the world (anchor) frame
  double width_m = 0;          // Plane: extent along local x, centred on the origin
  double height_m = 0;         // Plane: extent along local y
  double radius_m = 0;         // Sphere: centred on the local origin
  std::filesystem::path mesh_path;  // Mesh: glTF 2.0, loaded with core/scene/gltf_loader.h, or
  std::string mesh_builtin;         //   a builtin mesh ("builtin:cube": core/scene/builtin_meshes.h)
  // Mesh, the sized builtins ("builtin:box", "builtin:cylinder", "builtin:plane"; see
  // builtin_mesh_is_sized): made at this size x, y, z in metres (the plane ignores z); nullopt:
  // the builtin's default size.
  std::optional<Vec3> mesh_size_m;
  double mesh_scale = 1.0;          // Mesh: uniform scale applied in the object frame (after the size)
  SimMaterial material;
  bool is_virtual = false;  // left out of the camera frames, drawn only in the ground-truth composite
  bool casts_shadows = true;
  // A pose track (object_pose_at): empty for an object that stands still at T_world_object. The
  // loader makes T_world_object the first key's pose, where the object stands before that key.
  std::vector<SimPoseKey> keyframes;
};
inline constexpr ChoiceName<SimObject::Shape> kSimShapeNames[] = {
    {"plane", SimObject::Shape::Plane}, {"sphere", SimObject::Shape::Sphere}, {"mesh", SimObject::Shape::Mesh}};

struct SimLight {
  enum class Kind { Directional, Point, Sphere };
  std::string name;
  Kind kind = Kind::Directional;
  Rgb color{1, 1, 1};  // linear RGB, multiplies the strength below
  // Directional: unit vector from the scene towards the light (world), irradiance on a surface
  // facing it (W/m^2), and the angular diameter of the disc it comes from (0: a hard shadow).
  Vec3 direction_to_light{0, 0, 1};
  double irradiance = 0;
  double angular_diameter_rad = 0;
  // Point and Sphere: position (world) and radiant intensity (W/sr, as seen from far away; a
  // sphere's surface radiance is intensity / (pi r^2)).
  Vec3 position{0, 0, 0};
  double intensity = 0;
  double radius_m = 0;  // Sphere only
  bool is_sun = false;  // made from the scene's [sun] table
};
inline constexpr ChoiceName<SimLight::Kind> kSimLightKindNames[] = {{"directional", SimLight::Kind::Directional},
                                                                    {"point", SimLight::Kind::Point},
                                                                    {"sphere", SimLight::Kind::Sphere}};

// The sun of an outdoor scene: given as azimuth (east of true north) and elevation, so that a
// test can compare an estimate against exactly these numbers. The loader turns it into a
// Directional SimLight (is_sun) with angular diameter 0.53 degrees unless the file says otherwise.
struct SimSun {
  double azimuth_rad = 0;
  double elevation_rad = 0;
};

// The sky and ambient light: an equirectangular HDR image (.hdr, linear), else a constant colour.
// Direction d (world) maps to u = (atan2(d.y, d.x) + rotation) / (2 pi) wrapped to [0,1), v =
// acos(d.z) / pi: world +z (up) is the top row; rotation_rad turns the image about +z.
struct SimEnvironment {
  std::filesystem::path hdr_path;  // empty: constant `radiance`
  Rgb radiance{0, 0, 0};           // constant sky radiance, or a multiplier of the HDR image
  double rotation_rad = 0;
};

// A camera pose keyframe: the camera centre and what it looks at, in the world frame.
struct SimKeyframe {
  double time_s = 0;    // since the first frame's exposure start; strictly increasing
  Vec3 position{0, 0, 1};
  Vec3 look_at{0, 0, 0};
  Vec3 up{0, 0, 1};     // world direction that should point up in the image (need not be exact)
  double roll_rad = 0;  // extra rotation about the viewing direction, clockwise in the image
};

// A seeded random smooth path: the camera orbits `target` at distance in [min, max] and elevation
// in [min, max] above the world xy plane, wandering smoothly; the speeds are scaled so that the
// largest image motion during one exposure is max_blur_px (0: a still camera at the start pose).
struct SimRandomPath {
  Vec3 target{0, 0, 0};
  double min_distance_m = 0.4;
  double max_distance_m = 0.6;
  double min_elevation_rad = 0.9;  // above the xy plane
  double max_elevation_rad = 1.4;
  double max_blur_px = 10;
};

struct SimTrajectory {
  enum class Kind { Keyframes, Random };
  Kind kind = Kind::Keyframes;
  std::vector<SimKeyframe> keyframes;  // one keyframe: a still camera
  SimRandomPath random;
};
inline constexpr ChoiceName<SimTrajectory::Kind> kSimTrajectoryKindNames[] = {
    {"keyframes", SimTrajectory::Kind::Keyframes}, {"random", SimTrajectory::Kind::Random}};

// The sensor: linear value = radiance * exposure (s) * sensitivity, in units of full scale (1.0 =
// full well); photon shot noise at full_well_electrons, read noise in electrons, then analogue
// and digital gain, clipping, the response curve and 8-bit quantisation.
struct SimSensor {
  double sensitivity = 100.0;           // full-scale units per (W/m^2/sr * s)
  double full_well_electrons = 10000.0;
  double read_noise_electrons = 3.0;
  bool noise = true;                    // false: a noise-free sensor (exact tests)
  CameraResponse response;              // "srgb" (default), "linear" or "gamma:<g>" (value^(1/g))
  // Raw (Bayer) formats only: the code of zero light at the format's bit depth (e.g. 64 at 10
  // bits); full scale is the top code, 2^bits - 1. Raw values are linear: no response curve.
  int black_level = 0;
};

// Auto-exposure: after each frame, scale the next exposure so the mean linear value of the frame
// approaches `target`, within [min_exposure, frame interval]; gain rises only when exposure is at
// its maximum.
struct SimAutoExposure {
  bool enabled = false;
  double target = 0.18;
  int64_t min_exposure_ns = 100'000;
  double max_gain = 8.0;
};

// An omnidirectional-stereo pair ([camera.stereo], a LENSMODEL_LONLAT camera's): each pixel's ray
// leaves its eye on a circle about the camera's vertical axis (core/geometry/ods_projection.h),
// and each frame holds the left eye's image above the right's (top_bottom) or left of it. The
// camera model is one eye's.
struct SimStereo {
  bool enabled = false;
  bool top_bottom = true;
  OdsRig rig;
};

// The lens's own effects on the image, applied to the linear radiance image before the sensor
// (capture/sim/lens_optics.h): first defocus, then vignetting. The defaults change nothing.
struct SimOptics {
  // Defocus: a uniform disc point-spread function of this diameter (the circle of confusion) in
  // pixels; 0: in focus.
  double defocus_px = 0;
  // Vignetting: the lens's relative illumination (1 - v) + v cos^4(theta), theta the angle of the
  // pixel's ray from the optical axis (cos clamped at 0); 0: none, 1: the full cos^4 law.
  double vignetting = 0;
  bool active() const { return defocus_px > 0 || vignetting > 0; }
};

struct SimCamera {
  CameraModel model = CameraModel::pinhole(500, 500, 319.5, 239.5, 640, 480);
  PixelFormat pixel_format = PixelFormat::YUYV;
  double fps = 30.0;
  std::vector<int64_t> exposure_ns{4'000'000};  // per frame, cycled (one entry: fixed)
  double analogue_gain = 1.0;
  double digital_gain = 1.0;
  int64_t readout_ns = 0;  // first row to last row; 0: global shutter
  // The timestamp the simulated driver reports, and the per-camera offset that turns it back
  // into the exposure start (docs/DESIGN.md "Time"): raw = exposure_start - offset (+ exposure +
  // readout for EndOfFrame).
  TimestampMeaning timestamp_meaning = TimestampMeaning::StartOfExposure;
  int64_t timestamp_offset_ns = 0;
  int64_t first_exposure_start_ns = 1'000'000'000;
  SimAutoExposure auto_exposure;
  SimSensor sensor;
  SimStereo stereo;
  SimOptics optics;
  // Each written frame is encoded to JPEG at this quality (1..100) and decoded back into its
  // pixels (capture/sim/jpeg_round_trip.h); 0: off. Not for Bayer formats.
  int jpeg_quality = 0;

  // The frame's size: one eye's (the model's), or the stereo pair's.
  int frame_width() const { return stereo.enabled && !stereo.top_bottom ? 2 * model.width() : model.width(); }
  int frame_height() const { return stereo.enabled && stereo.top_bottom ? 2 * model.height() : model.height(); }
};

// sqrt(samples_per_pixel) when it is a perfect square of at least 1, else 0.
int samples_per_axis(int samples_per_pixel);

struct SimRender {
  int samples_per_pixel = 16;  // a square number: stratified sqrt x sqrt in the pixel, stratified in time
  int frames = 30;             // default for `arpipe simulate` without --frames
  uint64_t seed = 1;
  bool write_linear = false;   // also write the noise-free linear image of every frame
};

struct SimScene {
  std::filesystem::path source_file;  // the scene file, for messages
  std::string description;            // the file's `description`
  SimCamera camera;
  SimTrajectory trajectory;
  std::vector<SimObject> objects;
  std::vector<SimLight> lights;  // the sun, when given, is one of them (is_sun)
  std::optional<SimSun> sun;
  Vec3 world_north{0, 1, 0};     // true north in the world frame (horizontal); east = north x up
  SimEnvironment environment;
  SimRender render;

  bool has_virtual_objects() const;
  // Whether an object has a pose track (keyframes), so that the world changes from frame to frame.
  bool has_animated_objects() const;
};

// Where an object stands at trajectory time t_s: T_world_object without keys; else the end keys'
// poses outside their times (also for a NaN time: the first's), and between two keys
// SE3::interpolate (translation linear, rotation slerped the short way at constant speed): glTF's
// LINEAR translation and rotation channels with the same keys.
SE3 object_pose_at(const SimObject& object, double t_s);
// The scene as a still at trajectory time t_s: every object placed at object_pose_at(t_s), its
// keys dropped. What frame k of a video of the scene shows (t_s = its exposure start, k / fps).
SimScene scene_at_time(const SimScene& scene, double t_s);

}  // namespace arpipe::sim
