// Scene-file loader: the example scenes load and hold what their comments promise, units and
// derived values are right by hand computation, and every kind of bad input names file, line, key.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <string>
#include <vector>

#include "capture/sim/sim_scene_loader.h"
#include "core/config/config.h"

namespace arpipe::sim {
namespace {

namespace fs = std::filesystem;

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;
// Values computed in double from a few decimal inputs: a handful of rounding steps.
constexpr double kExact = 1e-12;

const fs::path kScenes = fs::path(ARPIPE_SOURCE_DIR) / "configs" / "sim";

SimScene parse(const std::string& text, const fs::path& base = {}) { return parse_sim_scene(text, "scene.toml", base); }

// The message of the SceneError that `text` raises, or "" (a test failure) when it loads.
std::string error_of(const std::string& text, const fs::path& base = {}) {
  try {
    parse(text, base);
  } catch (const SceneError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no SceneError for:\n" << text;
  return "";
}

// The message names the file and line ("scene.toml:<line>:<col>: ") and the dotted key.
void expect_error(const std::string& text, int line, const std::string& key, const std::string& also = "",
                  const fs::path& base = {}) {
  const std::string message = error_of(text, base);
  EXPECT_EQ(message.rfind("scene.toml:" + std::to_string(line) + ":", 0), 0u) << message;
  EXPECT_NE(message.find(" " + key + ": "), std::string::npos) << "key " << key << " not in: " << message;
  if (!also.empty()) {
    EXPECT_NE(message.find(also), std::string::npos) << "'" << also << "' not in: " << message;
  }
}

void expect_near(const Vec3& actual, const Vec3& expected, double tolerance) {
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(actual[i], expected[i], tolerance) << "component " << i;
}

// An independent look-at pose (camera x right, y down, z forward; image up near `up`; roll
// clockwise in the image), to check what the keyframes of the example scenes show.
SE3 look_at_pose(const SimKeyframe& k) {
  const Vec3 z = normalized(k.look_at - k.position);
  const Vec3 down = -1.0 * k.up;
  Vec3 y = normalized(down - dot(down, z) * z);
  Vec3 x = cross(y, z);
  const Vec3 x_rolled = std::cos(k.roll_rad) * x + std::sin(k.roll_rad) * y;
  y = cross(z, x_rolled);
  x = x_rolled;
  const Mat3 R{{{x[0], x[1], x[2]}, {y[0], y[1], y[2]}, {z[0], z[1], z[2]}}};
  return SE3(R, -1.0 * mat_mul(R, k.position));
}

// The smallest distance of a projected point from the image border (negative: outside, or
// behind the camera).
double inside_margin(const CameraModel& model, const SE3& T_cam_world, const Vec3& p_world) {
  const Vec3 p = T_cam_world * p_world;
  if (p[2] <= 0) return -1e9;
  const auto px = model.project(p);
  if (!px) return -1e9;
  return std::min({(*px)[0], (*px)[1], model.width() - 1 - (*px)[0], model.height() - 1 - (*px)[1]});
}

// Largest image speed (px/s) of the image centre's ray between consecutive keyframes: the
// angle between viewing directions over the time between them, times the focal length. A
// chord-based lower estimate of the smooth path's peak speed.
double max_chord_speed_px_s(const SimScene& scene) {
  const auto& k = scene.trajectory.keyframes;
  double fastest = 0;
  for (size_t i = 1; i < k.size(); ++i) {
    const Vec3 a = normalized(k[i - 1].look_at - k[i - 1].position);
    const Vec3 b = normalized(k[i].look_at - k[i].position);
    const double angle = std::atan2(norm(cross(a, b)), dot(a, b));
    fastest = std::max(fastest, scene.camera.model.fx() * angle / (k[i].time_s - k[i - 1].time_s));
  }
  return fastest;
}

const SimObject& object_named(const SimScene& scene, const std::string& name) {
  for (const auto& object : scene.objects)
    if (object.name == name) return object;
  throw std::runtime_error("no object " + name);
}

class TempDir {
 public:
  TempDir() {
    const auto stamp = std::chrono::steady_clock::now().time_since_epoch().count();
    path_ = fs::temp_directory_path() / ("arpipe-sim-scene-" + std::to_string(stamp) + "-" +
                                         ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  const fs::path& path() const { return path_; }
  fs::path write(const std::string& name, const std::string& content) const {
    std::ofstream(path_ / name, std::ios::binary) << content;
    return path_ / name;
  }

 private:
  fs::path path_;
};

// One triangle in the xy plane, its buffer embedded as a data URI.
const char* kTriangleGltf = R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],
"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],
"buffers":[{"byteLength":36,"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}],
"bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":36}],
"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}]})";

// ---- The example scenes --------------------------------------------------------------------------

TEST(SimSceneLoaderExamples, EveryExampleLoadsAndSaysWhatItIsFor) {
  const std::set<std::string> expected{"blur-bench.toml", "calib-board.toml", "calib-board-photo.toml", "calib-charuco.toml", "default.toml", "probe-indoor.toml", "rolling-shutter.toml",
                                       "proxies.toml", "proxies-panorama.toml", "hybrid-animated.toml", "courtyard.toml", "sun-outdoor.toml",
                                       "tag-pan.toml", "tag-static.toml"};
  std::set<std::string> found;
  for (const auto& entry : fs::directory_iterator(kScenes)) {
    if (entry.path().extension() != ".toml") continue;
    found.insert(entry.path().filename().string());
    SCOPED_TRACE(entry.path().string());
    SimScene scene;
    ASSERT_NO_THROW(scene = load_sim_scene(entry.path()));
    EXPECT_EQ(scene.source_file, entry.path());
    EXPECT_FALSE(scene.description.empty());
    // Every example starts with comments saying what it is for.
    std::ifstream in(entry.path());
    std::string first;
    std::getline(in, first);
    EXPECT_EQ(first.rfind("# ", 0), 0u) << first;
    if (entry.path().filename() == "proxies-panorama.toml" || entry.path().filename() == "courtyard.toml" ||
        entry.path().filename() == "hybrid-animated.toml") {
      // A panorama: the whole sphere in the equirectangular layout (fx = W / 2 pi, fy = H / pi, centred).
      const CameraModel& m = scene.camera.model;
      EXPECT_EQ(m.lensmodel(), "LENSMODEL_LONLAT");
      EXPECT_EQ(m.width(), 2 * m.height());
      EXPECT_NEAR(m.fx(), m.width() / (2 * M_PI), 1e-9);
      EXPECT_NEAR(m.fy(), m.height() / M_PI, 1e-9);
      EXPECT_EQ(m.cx(), (m.width() - 1) / 2.0);
      EXPECT_EQ(m.cy(), (m.height() - 1) / 2.0);
      continue;
    }
    // The common camera: 640x480, the mild OPENCV4 lens (calib-board and calib-board-photo: the
    // wide OPENCV8 one that calibration must recover).
    EXPECT_EQ(scene.camera.model.width(), 640);
    EXPECT_EQ(scene.camera.model.height(), 480);
    const bool calibration =
        entry.path().filename() == "calib-board.toml" || entry.path().filename() == "calib-board-photo.toml" ||
        entry.path().filename() == "calib-charuco.toml";
    EXPECT_EQ(scene.camera.model.lensmodel(), calibration ? "LENSMODEL_OPENCV8" : "LENSMODEL_OPENCV4");
    EXPECT_EQ(scene.camera.model.fx(), 520.0);
  }
  for (const auto& name : expected) EXPECT_EQ(found.count(name), 1u) << name;
}

// The anchor tag: tag36h11 id 0 with a 0.10 m black border, lying at the origin of the world, on
// a table just below it (every scene but the chessboard's).
void expect_anchor_on_table(const SimScene& scene) {
  const SimObject& anchor = object_named(scene, "anchor");
  EXPECT_EQ(anchor.material.texture.kind, SimTexture::Kind::AprilTag);
  EXPECT_EQ(anchor.material.texture.family, "tag36h11");
  EXPECT_EQ(anchor.material.texture.tag_id, 0);
  EXPECT_NEAR(anchor.width_m, 0.125, kExact);  // 0.10 m * total_width 10 / width_at_border 8
  expect_near(anchor.T_world_object.translation(), {0, 0, 0}, 0);
  EXPECT_EQ(anchor.T_world_object.rotation(), identity3());
  const SimObject& ground = scene.objects.front();
  EXPECT_EQ(ground.shape, SimObject::Shape::Plane);
  EXPECT_NEAR(ground.T_world_object.translation()[2], -0.0005, kExact);
  EXPECT_GE(ground.width_m, 2.0);
}

TEST(SimSceneLoaderExamples, TagStaticIsAStillNoisyCameraOverTheAnchor) {
  const SimScene scene = load_sim_scene(kScenes / "tag-static.toml");
  expect_anchor_on_table(scene);
  ASSERT_EQ(scene.trajectory.kind, SimTrajectory::Kind::Keyframes);
  EXPECT_EQ(scene.trajectory.keyframes.size(), 1u);
  EXPECT_TRUE(scene.camera.sensor.noise);
  // The whole tag with its white border in view, well inside the image.
  const SE3 T = look_at_pose(scene.trajectory.keyframes[0]);
  for (double sx : {-1.0, 1.0})
    for (double sy : {-1.0, 1.0}) {
      EXPECT_GT(inside_margin(scene.camera.model, T, {sx * 0.0625, sy * 0.0625, 0}), 100);
    }
}

TEST(SimSceneLoaderExamples, TagPanBlursUpToAbout30Px) {
  const SimScene scene = load_sim_scene(kScenes / "tag-pan.toml");
  expect_anchor_on_table(scene);
  EXPECT_EQ(scene.camera.exposure_ns, std::vector<int64_t>{8'000'000});
  for (const auto& k : scene.trajectory.keyframes) expect_near(k.position, {0, -0.3, 0.4}, 0);  // a pan: turning only
  // Chord speed x exposure: a lower estimate of the peak blur (the smooth path peaks up to ~25%
  // above its chords), so "up to about 30 px" means a chord blur of 20-30 px.
  const double blur = max_chord_speed_px_s(scene) * 8e-3;
  EXPECT_GT(blur, 20.0);
  EXPECT_LT(blur, 30.0);
}

TEST(SimSceneLoaderExamples, RollingShutterReadsOutOver25MsWhilePanning) {
  const SimScene scene = load_sim_scene(kScenes / "rolling-shutter.toml");
  expect_anchor_on_table(scene);
  EXPECT_EQ(scene.camera.readout_ns, 25'000'000);
  EXPECT_EQ(scene.camera.fps, 30.0);
  EXPECT_EQ(scene.camera.timestamp_meaning, TimestampMeaning::EndOfFrame);
  // About 1000 px/s: some 25 px of skew from the top row to the bottom row, blur well below it.
  const double speed = max_chord_speed_px_s(scene);
  EXPECT_GT(speed * 0.025, 15.0);
  EXPECT_LT(speed * 0.025, 35.0);
  EXPECT_LT(speed * scene.camera.exposure_ns.front() * 1e-9, speed * 0.025 / 5);
}

TEST(SimSceneLoaderExamples, CalibBoardShowsTheWholeBoardAllOverTheImage) {
  const SimScene scene = load_sim_scene(kScenes / "calib-board.toml");
  const SimObject& board = object_named(scene, "board");
  const SimTexture& t = board.material.texture;
  ASSERT_EQ(t.kind, SimTexture::Kind::Chessboard);
  EXPECT_EQ(t.rows, 10);
  EXPECT_EQ(t.cols, 14);
  EXPECT_NEAR(board.width_m, (14 + 2) * 0.02, kExact);  // one margin square each side
  EXPECT_NEAR(board.height_m, (10 + 2) * 0.02, kExact);
  EXPECT_EQ(scene.camera.fps, 2.0);
  EXPECT_TRUE(scene.camera.sensor.noise);
  const auto& keys = scene.trajectory.keyframes;
  ASSERT_EQ(keys.size(), 60u);
  EXPECT_EQ(scene.render.frames, 60);
  std::set<std::pair<int, int>> cells;  // 3x3 regions of the image where the board's centre lies
  for (size_t i = 0; i < keys.size(); ++i) {
    EXPECT_DOUBLE_EQ(keys[i].time_s, double(i) / scene.camera.fps) << "keyframe " << i << " is not frame " << i;
    const SE3 T = look_at_pose(keys[i]);
    for (int row = 0; row <= 8; ++row)
      for (int col = 0; col <= 12; ++col) {
        EXPECT_GT(inside_margin(scene.camera.model, T, {-0.12 + 0.02 * col, 0.08 - 0.02 * row, 0}), 10.0)
            << "keyframe " << i << " corner " << row << "," << col;
      }
    for (double sx : {-1.0, 1.0})  // the paper's corners too: detectors want the white margin
      for (double sy : {-1.0, 1.0}) {
        EXPECT_GT(inside_margin(scene.camera.model, T, {sx * 0.16, sy * 0.12, 0}), 0.0) << "keyframe " << i;
      }
    const auto centre = scene.camera.model.project(T * Vec3{0, 0, 0});
    ASSERT_TRUE(centre);
    cells.insert({int((*centre)[0] / (640 / 3.0)), int((*centre)[1] / (480 / 3.0))});
  }
  EXPECT_EQ(cells.size(), 9u) << "the board should appear in every ninth of the image";
  // Blur-free: the chord speed of the image centre over the 0.2 ms exposure is a fraction of a pixel.
  EXPECT_LT(max_chord_speed_px_s(scene) * scene.camera.exposure_ns.front() * 1e-9, 0.5);
}

TEST(SimSceneLoaderExamples, ProbeIndoorHasProbesLightsAShadowCasterAndAVirtualObject) {
  const SimScene scene = load_sim_scene(kScenes / "probe-indoor.toml");
  expect_anchor_on_table(scene);
  const SimObject& mirror = object_named(scene, "mirror_probe");
  EXPECT_EQ(mirror.shape, SimObject::Shape::Sphere);
  EXPECT_EQ(mirror.material.kind, SimMaterial::Kind::Mirror);
  EXPECT_EQ(mirror.radius_m, 0.04);
  const SimObject& diffuse = object_named(scene, "diffuse_probe");
  EXPECT_EQ(diffuse.material.kind, SimMaterial::Kind::Lambertian);
  for (const SimObject* sphere : {&mirror, &diffuse})  // resting on the table top
    EXPECT_NEAR(sphere->T_world_object.translation()[2] - sphere->radius_m, -0.0005, kExact);
  EXPECT_EQ(object_named(scene, "tag1").material.texture.tag_id, 1);
  // The card stands up: rotation_deg [90, 0, 0] turns its local y (printed top) to world z.
  const SimObject& card = object_named(scene, "card");
  expect_near(card.T_world_object.rotate({0, 1, 0}), {0, 0, 1}, kExact);
  expect_near(card.T_world_object.rotate({0, 0, 1}), {0, -1, 0}, kExact);
  EXPECT_TRUE(card.casts_shadows);
  EXPECT_FALSE(card.is_virtual);
  EXPECT_TRUE(scene.has_virtual_objects());
  EXPECT_TRUE(object_named(scene, "virtual_ball").is_virtual);
  ASSERT_EQ(scene.lights.size(), 2u);
  EXPECT_EQ(scene.lights[0].kind, SimLight::Kind::Sphere);  // the mirror shows it
  EXPECT_GT(scene.lights[0].radius_m, 0);
  EXPECT_EQ(scene.lights[1].kind, SimLight::Kind::Point);
  EXPECT_LT(scene.lights[1].intensity, scene.lights[0].intensity / 4);  // a weaker fill
  EXPECT_FALSE(scene.sun);
}

TEST(SimSceneLoaderExamples, SunOutdoorHasTheSunWhereItsCommentSays) {
  const SimScene scene = load_sim_scene(kScenes / "sun-outdoor.toml");
  ASSERT_TRUE(scene.sun);
  EXPECT_NEAR(scene.sun->azimuth_rad, 135 * kDeg, kExact);
  EXPECT_NEAR(scene.sun->elevation_rad, 40 * kDeg, kExact);
  ASSERT_EQ(scene.lights.size(), 1u);
  const SimLight& sun = scene.lights[0];
  EXPECT_TRUE(sun.is_sun);
  EXPECT_EQ(sun.name, "sun");
  EXPECT_EQ(sun.kind, SimLight::Kind::Directional);
  // North = +y, so east = +x: [sin 135 cos 40, cos 135 cos 40, sin 40], by hand.
  const double c40 = 0.766044443118978, s40 = 0.642787609686539, r = std::sqrt(0.5);
  expect_near(sun.direction_to_light, {r * c40, -r * c40, s40}, kExact);
  EXPECT_NEAR(sun.angular_diameter_rad, 0.53 * kDeg, kExact);
  EXPECT_GT(scene.environment.radiance[2], scene.environment.radiance[0]);  // blue-ish sky
  EXPECT_TRUE(scene.environment.hdr_path.empty());
  EXPECT_TRUE(scene.has_virtual_objects());
  EXPECT_FALSE(object_named(scene, "ball").is_virtual);
  expect_anchor_on_table(scene);
}

TEST(SimSceneLoaderExamples, DefaultIsTheCheapEmbeddedCapture) {
  const SimScene scene = load_sim_scene(kScenes / "default.toml");
  expect_anchor_on_table(scene);
  EXPECT_EQ(scene.camera.pixel_format, PixelFormat::YUYV);
  EXPECT_EQ(scene.camera.fps, 30.0);
  EXPECT_EQ(scene.render.frames, 60);
  EXPECT_EQ(scene.render.samples_per_pixel, 4);
  ASSERT_EQ(scene.lights.size(), 1u);
  EXPECT_EQ(scene.lights[0].kind, SimLight::Kind::Directional);
  EXPECT_TRUE(scene.environment.hdr_path.empty());
  EXPECT_GT(scene.environment.radiance[0], 0);
  // Its one virtual object is the one configs/arpipe.toml draws, so that the ground-truth
  // composite is what arpiped's composite should be.
  const Config config = load_config(fs::path(ARPIPE_SOURCE_DIR) / "configs" / "arpipe.toml");
  ASSERT_EQ(config.render.objects.size(), 1u);
  const SceneObject& drawn = config.render.objects[0];
  const auto is_virtual = [](const SimObject& o) { return o.is_virtual; };
  ASSERT_EQ(std::count_if(scene.objects.begin(), scene.objects.end(), is_virtual), 1);
  const SimObject& cube = *std::find_if(scene.objects.begin(), scene.objects.end(), is_virtual);
  EXPECT_EQ(cube.mesh_builtin, drawn.mesh);
  EXPECT_EQ(cube.T_world_object.translation(), drawn.position_m);
  EXPECT_EQ(cube.T_world_object.rotation_vector()[2], drawn.yaw_rad);
  EXPECT_EQ(cube.mesh_scale, drawn.scale);
  EXPECT_EQ(cube.material.albedo, (Rgb{drawn.color[0], drawn.color[1], drawn.color[2]}));
  // The tag is in full view at the start and out of view at the last keyframe (t = 2 s, after
  // the last frame's exposure start at 59/30 s).
  const auto& keys = scene.trajectory.keyframes;
  const double h = 0.0625;
  for (double sx : {-1.0, 1.0})
    for (double sy : {-1.0, 1.0}) {
      EXPECT_GT(inside_margin(scene.camera.model, look_at_pose(keys.front()), {sx * h, sy * h, 0}), 50);
      EXPECT_LT(inside_margin(scene.camera.model, look_at_pose(keys.back()), {sx * h, sy * h, 0}), -50);
    }
  EXPECT_GE(keys.back().time_s, 59 / 30.0);
}

// ---- Values and units ------------------------------------------------------------------------

TEST(SimSceneLoaderValues, EmptyFileGivesTheDocumentedDefaults) {
  const SimScene scene = parse("");
  EXPECT_EQ(scene.source_file, "scene.toml");
  EXPECT_EQ(scene.camera.model.lensmodel(), "LENSMODEL_PINHOLE");
  EXPECT_EQ(scene.camera.model.width(), 640);
  EXPECT_EQ(scene.camera.pixel_format, PixelFormat::YUYV);
  EXPECT_EQ(scene.camera.fps, 30.0);
  EXPECT_EQ(scene.camera.exposure_ns, std::vector<int64_t>{4'000'000});
  EXPECT_EQ(scene.camera.first_exposure_start_ns, 1'000'000'000);
  EXPECT_EQ(scene.render.samples_per_pixel, 16);
  ASSERT_EQ(scene.trajectory.keyframes.size(), 1u);  // a still camera south of the origin
  expect_near(scene.trajectory.keyframes[0].position, {0, -0.3, 0.4}, 0);
  EXPECT_TRUE(scene.objects.empty());
  EXPECT_TRUE(scene.lights.empty());
  EXPECT_FALSE(scene.sun);
  expect_near(scene.world_north, {0, 1, 0}, 0);
}

TEST(SimSceneLoaderValues, MillisecondsBecomeNanosecondsAndDegreesRadians) {
  const SimScene scene = parse(
      "[camera]\n"
      "fps = 25\n"
      "exposure_ms = [1, 2.5, 40]\n"
      "readout_ms = 12.345678\n"
      "timestamp = \"end_of_frame\"\n"
      "timestamp_offset_ms = -0.25\n"
      "first_exposure_start_ms = 2000.5\n"
      "[camera.auto_exposure]\n"
      "enabled = true\n"
      "min_exposure_ms = 0.05\n"
      "[[trajectory.keyframe]]\n"
      "roll_deg = 90\n"
      "[[light]]\n"
      "direction = [0, 3, 4]\n"
      "angular_diameter_deg = 2\n"
      "[environment]\n"
      "rotation_deg = -45\n");
  EXPECT_EQ(scene.camera.exposure_ns, (std::vector<int64_t>{1'000'000, 2'500'000, 40'000'000}));
  EXPECT_EQ(scene.camera.readout_ns, 12'345'678);
  EXPECT_EQ(scene.camera.timestamp_meaning, TimestampMeaning::EndOfFrame);
  EXPECT_EQ(scene.camera.timestamp_offset_ns, -250'000);
  EXPECT_EQ(scene.camera.first_exposure_start_ns, 2'000'500'000);
  EXPECT_TRUE(scene.camera.auto_exposure.enabled);
  EXPECT_EQ(scene.camera.auto_exposure.min_exposure_ns, 50'000);
  EXPECT_NEAR(scene.trajectory.keyframes[0].roll_rad, kPi / 2, kExact);
  expect_near(scene.lights[0].direction_to_light, {0, 0.6, 0.8}, kExact);  // normalised
  EXPECT_NEAR(scene.lights[0].angular_diameter_rad, 2 * kDeg, kExact);
  EXPECT_NEAR(scene.environment.rotation_rad, -kPi / 4, kExact);
}

TEST(SimSceneLoaderValues, RotationIsARotationVectorInDegrees) {
  const SimScene scene = parse(
      "[[object]]\n"
      "position = [1, 2, 3]\n"
      "rotation_deg = [0, 0, 90]\n"
      "[[object]]\n"
      "rotation_deg = [60, 60, 60]\n");
  // 90 degrees about z: x -> y.
  expect_near(scene.objects[0].T_world_object.rotate({1, 0, 0}), {0, 1, 0}, kExact);
  expect_near(scene.objects[0].T_world_object.translation(), {1, 2, 3}, 0);
  // Axis (1,1,1)/sqrt3, angle 60 sqrt3 = 103.92 degrees: the axis itself stays put, and the angle
  // between x and its image is fixed by the Rodrigues formula: cos = c + (1-c)/3.
  const SE3& T = scene.objects[1].T_world_object;
  expect_near(T.rotate({1, 1, 1}), {1, 1, 1}, kExact);
  const double c = std::cos(60 * std::sqrt(3.0) * kDeg);
  EXPECT_NEAR(dot(T.rotate({1, 0, 0}), {1, 0, 0}), c + (1 - c) / 3, kExact);
}

TEST(SimSceneLoaderValues, AprilTagPlaneIsTheWholePatternAroundTheBlackBorder) {
  // size_m * total_width / width_at_border, from libapriltag's layouts (36h11: 10/8, 16h5: 8/6,
  // Standard41h12: 9/5, whose black border lies inside the white one).
  const struct {
    const char* family;
    double ratio;
  } cases[] = {{"tag36h11", 10.0 / 8}, {"tag16h5", 8.0 / 6}, {"tagStandard41h12", 9.0 / 5}};
  for (const auto& c : cases) {
    const SimScene scene =
        parse(std::string("[[object]]\n[object.texture]\nkind = \"apriltag\"\nsize_m = 0.16\nfamily = \"") + c.family +
              "\"\nid = 3\n");
    EXPECT_NEAR(scene.objects[0].width_m, 0.16 * c.ratio, kExact) << c.family;
    EXPECT_NEAR(scene.objects[0].height_m, 0.16 * c.ratio, kExact) << c.family;
    EXPECT_EQ(scene.objects[0].material.texture.tag_id, 3);
  }
}

TEST(SimSceneLoaderValues, ChessboardPlaneIsTheBoardPlusItsMargin) {
  const SimScene scene = parse(
      "[[object]]\n[object.texture]\nkind = \"chessboard\"\nrows = 6\ncols = 9\nsquare_m = 0.025\nmargin_squares = "
      "0.5\n");
  EXPECT_NEAR(scene.objects[0].width_m, (9 + 1) * 0.025, kExact);
  EXPECT_NEAR(scene.objects[0].height_m, (6 + 1) * 0.025, kExact);
}

TEST(SimSceneLoaderSun, DirectionFollowsEastNorthUp) {
  const double r = std::sqrt(0.5);
  const struct {
    const char* north;
    double azimuth, elevation;
    Vec3 expected;
  } cases[] = {
      {"[0, 1, 0]", 90, 0, {1, 0, 0}},     // east = north x up = +x
      {"[0, 1, 0]", 0, 0, {0, 1, 0}},      // north
      {"[0, 1, 0]", 180, 45, {0, -r, r}},  // south, half way up
      {"[0, 1, 0]", 270, 0, {-1, 0, 0}},   // west
      {"[0, 1, 0]", 10, 90, {0, 0, 1}},    // the zenith, whatever the azimuth
      {"[1, 0, 0]", 90, 0, {0, -1, 0}},    // north = +x: east = x cross z = -y
      {"[3, 4, 0]", 0, 30, {0.6 * std::sqrt(3.0) / 2, 0.8 * std::sqrt(3.0) / 2, 0.5}},  // north normalised
  };
  for (const auto& c : cases) {
    const SimScene scene =
        parse(std::string("[world]\nnorth = ") + c.north + "\n[sun]\nazimuth_deg = " + std::to_string(c.azimuth) +
              "\nelevation_deg = " + std::to_string(c.elevation) + "\n");
    SCOPED_TRACE(std::string(c.north) + " az " + std::to_string(c.azimuth) + " el " + std::to_string(c.elevation));
    ASSERT_EQ(scene.lights.size(), 1u);
    expect_near(scene.lights[0].direction_to_light, c.expected, kExact);
    EXPECT_TRUE(scene.lights[0].is_sun);
    EXPECT_NEAR(scene.sun->azimuth_rad, c.azimuth * kDeg, kExact);
  }
}

TEST(SimSceneLoaderFiles, RelativePathsAreRelativeToTheSceneFile) {
  const TempDir dir;
  fs::create_directories(dir.path() / "assets");
  cv::imwrite((dir.path() / "assets" / "photo.png").string(), cv::Mat(4, 4, CV_8UC3, cv::Scalar(10, 200, 30)));
  dir.write("assets/tri.gltf", kTriangleGltf);
  dir.write("assets/sky.hdr", "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 1\n\x80\x80\x80\x81");
  CameraModel("LENSMODEL_OPENCV4", {400, 410, 159.5, 119.5, -0.1, 0.01, 0, 0}, 320, 240)
      .save(dir.path() / "assets" / "cam.cameramodel");
  const fs::path scene_file =
      dir.write("scene.toml",
                "[camera]\nmodel = \"assets/cam.cameramodel\"\n"
                "[[object]]\nname = \"photo\"\nwidth_m = 0.3\nheight_m = 0.2\n"
                "[object.texture]\nkind = \"image\"\nimage = \"assets/photo.png\"\n"
                "[[object]]\nname = \"tri\"\nshape = \"mesh\"\nmesh = \"assets/tri.gltf\"\nmesh_scale = 2\n"
                "[environment]\nhdr = \"assets/sky.hdr\"\n");
  const SimScene scene = load_sim_scene(scene_file);
  EXPECT_EQ(scene.camera.model.width(), 320);
  EXPECT_EQ(scene.camera.model.fy(), 410);
  EXPECT_EQ(scene.objects[0].material.texture.kind, SimTexture::Kind::Image);
  EXPECT_TRUE(fs::equivalent(scene.objects[0].material.texture.image_path, dir.path() / "assets" / "photo.png"));
  EXPECT_EQ(scene.objects[0].width_m, 0.3);
  expect_near(scene.objects[0].material.albedo, {1, 1, 1}, 0);  // an image keeps its own colours by default
  EXPECT_EQ(scene.objects[1].shape, SimObject::Shape::Mesh);
  EXPECT_TRUE(fs::equivalent(scene.objects[1].mesh_path, dir.path() / "assets" / "tri.gltf"));
  EXPECT_EQ(scene.objects[1].mesh_scale, 2.0);
  EXPECT_TRUE(fs::equivalent(scene.environment.hdr_path, dir.path() / "assets" / "sky.hdr"));
  expect_near(scene.environment.radiance, {1, 1, 1}, 0);  // an HDR image's multiplier defaults to 1
}

// ---- Errors: each names the file, the line and the key ------------------------------------------

TEST(SimSceneLoaderErrors, TomlSyntax) {
  const std::string message = error_of("[camera]\nfps = 30\nexposure_ms = [4,\n");
  EXPECT_EQ(message.rfind("scene.toml:", 0), 0u) << message;
  EXPECT_NE(message.find("TOML syntax error"), std::string::npos) << message;
}

TEST(SimSceneLoaderErrors, UnknownKeysAnywhere) {
  expect_error("description = \"x\"\n[camra]\nfps = 30\n", 2, "camra", "unknown key");
  expect_error("[camera]\nfps = 30\n[camera.sensor]\nnoize = false\n", 4, "camera.sensor.noize", "unknown key");
  expect_error("[[object]]\nname = \"a\"\n[[object]]\nname = \"b\"\n[[object]]\nname = \"c\"\nwidht_m = 0.2\n", 7,
               "object[2].widht_m", "unknown key");
  expect_error("[[object]]\n[object.texture]\nkind = \"apriltag\"\nsize = 0.1\n", 4, "object[0].texture.size",
               "unknown key");
  expect_error("[[trajectory.keyframe]]\nlook_at = [0, 0, 0]\nlookat = [1, 0, 0]\n", 3, "trajectory.keyframe[0].lookat",
               "unknown key");
  expect_error("[[light]]\nkind = \"point\"\npower = 3\n", 3, "light[0].power", "unknown key");
  expect_error("[sun]\nazimuth = 10\n", 2, "sun.azimuth", "unknown key");
  // Keys that exist, in the wrong kind of entry.
  expect_error("[[object]]\nshape = \"plane\"\nradius_m = 0.1\n", 3, "object[0].radius_m", "sphere");
  expect_error("[[light]]\nkind = \"point\"\ndirection = [0, 0, 1]\n", 3, "light[0].direction", "directional");
}

TEST(SimSceneLoaderErrors, WrongTypes) {
  expect_error("[camera]\nfps = \"thirty\"\n", 2, "camera.fps", "a string");
  expect_error("[render]\nsamples_per_pixel = 4.0\n", 2, "render.samples_per_pixel", "a float");
  expect_error("\n[[object]]\nposition = [0, 0]\n", 3, "object[0].position", "2 items");
  expect_error("[[object]]\nvirtual = \"yes\"\n", 2, "object[0].virtual", "a string");
  expect_error("[object]\nname = \"x\"\n", 1, "object", "[[object]]");
  expect_error("[camera]\nexposure_ms = \"4\"\n", 2, "camera.exposure_ms", "a string");
  expect_error("[camera]\nexposure_ms = [4, \"8\"]\n", 2, "camera.exposure_ms[1]", "a string");
  expect_error("[[light]]\nkind = \"laser\"\n", 2, "light[0].kind", "\"laser\"");
  expect_error("[camera]\npixel_format = \"MJPG\"\n", 2, "camera.pixel_format", "\"MJPG\"");
  expect_error("[camera]\ntimestamp = \"start-of-exposure\"\n", 2, "camera.timestamp", "start_of_exposure");
  expect_error("[camera.sensor]\nresponse = \"gamma:-2\"\n", 2, "camera.sensor.response", "gamma:<g>");
}

TEST(SimSceneLoaderErrors, MissingOrUnreadableAssetsNameTheFile) {
  const TempDir dir;
  dir.write("not-an-image.png", "hello, I am text");
  dir.write("bad.gltf", "{ this is not json");
  dir.write("bad.hdr", "P6\n1 1\n255\nabc");
  dir.write("bad.cameramodel", "{ 'lensmodel': 'LENSMODEL_NOPE' }");
  const fs::path base = dir.path();
  expect_error("[[object]]\n[object.texture]\nkind = \"image\"\nimage = \"missing.png\"\n", 4,
               "object[0].texture.image", "missing.png", base);
  expect_error("[[object]]\n[object.texture]\nkind = \"image\"\nimage = \"not-an-image.png\"\n", 4,
               "object[0].texture.image", "not-an-image.png", base);
  expect_error("[[object]]\n[object.texture]\nkind = \"image\"\n", 2, "object[0].texture.image", "image file", base);
  expect_error("[[object]]\nshape = \"mesh\"\nmesh = \"missing.glb\"\n", 3, "object[0].mesh", "missing.glb", base);
  expect_error("[[object]]\nshape = \"mesh\"\nmesh = \"bad.gltf\"\n", 3, "object[0].mesh", "bad.gltf", base);
  expect_error("[[object]]\nshape = \"mesh\"\n", 1, "object[0].mesh", "glTF", base);
  expect_error("[environment]\nhdr = \"missing.hdr\"\n", 2, "environment.hdr", "missing.hdr", base);
  expect_error("[environment]\nhdr = \"bad.hdr\"\n", 2, "environment.hdr", "bad.hdr", base);
  expect_error("[camera]\nmodel = \"missing.cameramodel\"\n", 2, "camera.model", "missing.cameramodel", base);
  expect_error("[camera]\nmodel = \"bad.cameramodel\"\n", 2, "camera.model", "bad.cameramodel", base);
  expect_error("[camera]\nmodel = \"bad.cameramodel\"\nwidth = 640\n", 3, "camera.width", "model", base);
}

TEST(SimSceneLoaderErrors, ImpossibleTrajectories) {
  expect_error("[trajectory]\nkind = \"keyframes\"\n", 1, "trajectory.keyframe", "at least one");
  expect_error("[[trajectory.keyframe]]\ntime_s = 0.5\n[[trajectory.keyframe]]\ntime_s = 0.5\n", 4,
               "trajectory.keyframe[1].time_s", "strictly increase");
  expect_error(
      "[[trajectory.keyframe]]\ntime_s = 1\n[[trajectory.keyframe]]\ntime_s = 2\n[[trajectory.keyframe]]\ntime_s = "
      "1.5\n",
      6, "trajectory.keyframe[2].time_s", "strictly increase");
  expect_error("[[trajectory.keyframe]]\nposition = [0, 0, 1]\nlook_at = [0, 0, 1]\n", 3,
               "trajectory.keyframe[0].look_at", "other than the camera position");
  expect_error("[[trajectory.keyframe]]\nposition = [0, 0, 1]\nlook_at = [0, 0, 0]\nup = [0, 0, 2]\n", 4,
               "trajectory.keyframe[0].up", "parallel");
  // Straight down with the default up (+z): parallel too; the message points at the keyframe.
  expect_error("\n[[trajectory.keyframe]]\nposition = [0, 0, 1]\nlook_at = [0, 0, 0]\n", 2, "trajectory.keyframe[0].up",
               "the default");
  expect_error("[trajectory]\nkind = \"random\"\n[[trajectory.keyframe]]\n", 3, "trajectory.keyframe", "random");
  const std::string random = "[trajectory]\nkind = \"random\"\n[trajectory.random]\n";
  expect_error(random + "min_distance_m = 0.5\nmax_distance_m = 0.3\n", 5, "trajectory.random.max_distance_m", "0.3");
  expect_error(random + "min_distance_m = 0\n", 4, "trajectory.random.min_distance_m", "> 0");
  expect_error(random + "min_elevation_deg = 60\nmax_elevation_deg = 30\n", 5, "trajectory.random.max_elevation_deg",
               "min_elevation_deg <= max_elevation_deg");
  expect_error(random + "min_elevation_deg = -10\n", 4, "trajectory.random.min_elevation_deg", "(0, 90]");
  expect_error(random + "max_blur_px = 250\n", 4, "trajectory.random.max_blur_px", "[0, 200]");
  expect_error(random + "max_blur_px = -1\n", 4, "trajectory.random.max_blur_px", "[0, 200]");
}

TEST(SimSceneLoaderErrors, ExposureReadoutAndFrameRate) {
  expect_error("[camera]\nexposure_ms = 0\n", 2, "camera.exposure_ms", "> 0");
  expect_error("[camera]\nexposure_ms = -4\n", 2, "camera.exposure_ms", "> 0");
  expect_error("[camera]\nexposure_ms = []\n", 2, "camera.exposure_ms", "at least one");
  expect_error("[camera]\nfps = 30\nexposure_ms = 40\n", 3, "camera.exposure_ms", "frame interval 33.3333 ms");
  expect_error("[camera]\nfps = 30\nexposure_ms = [4, 34]\n", 3, "camera.exposure_ms[1]", "frame interval");
  expect_error("[camera]\nfps = 30\nreadout_ms = 35\n", 3, "camera.readout_ms", "frame interval");
  expect_error("[camera]\nreadout_ms = -1\n", 2, "camera.readout_ms", ">= 0");
  expect_error("[camera]\nfps = 0\n", 2, "camera.fps", "(0, 1000000]");
  expect_error("[camera]\nfps = -30\n", 2, "camera.fps", "(0, 1000000]");
  // The default 4 ms exposure does not fit 1000 frames/s.
  expect_error("[camera]\nfps = 1000\n", 2, "camera.fps", "exposure 4 ms");
  expect_error("[camera.auto_exposure]\nmax_gain = 0.5\n", 2, "camera.auto_exposure.max_gain", ">= 1");
  expect_error("[camera]\nanalogue_gain = 0\n", 2, "camera.analogue_gain", "> 0");
  // Times in int64 nanoseconds must not overflow.
  expect_error("[camera]\ntimestamp_offset_ms = 1e300\n", 2, "camera.timestamp_offset_ms", "1e+12 ms");
  expect_error("[camera]\nfirst_exposure_start_ms = 2e12\n", 2, "camera.first_exposure_start_ms", "1e+12 ms");
  expect_error("[camera]\nexposure_ms = [1e300]\n", 2, "camera.exposure_ms[0]", "frame interval");
}

TEST(SimSceneLoaderErrors, ImageSizeMustSuitThePixelFormat) {
  expect_error("[camera]\nwidth = 641\nheight = 480\npixel_format = \"YUYV\"\n", 4, "camera.pixel_format", "641x480");
  expect_error("[camera]\nwidth = 639\nheight = 480\n", 2, "camera.width", "639x480");  // YUYV by default
  expect_error("[camera]\nwidth = 640\nheight = 481\npixel_format = \"NV12\"\n", 4, "camera.pixel_format", "NV12");
  EXPECT_NO_THROW(parse("[camera]\nwidth = 641\nheight = 481\npixel_format = \"GREY\"\n"));
  expect_error("[camera]\nlensmodel = \"LENSMODEL_OPENCV4\"\nintrinsics = [520, 520, 320, 240]\n", 3,
               "camera.intrinsics", "LENSMODEL_OPENCV4");
  expect_error("[camera]\nlensmodel = \"LENSMODEL_OPENCV4\"\n", 1, "camera.intrinsics", "LENSMODEL_OPENCV4");
  expect_error("[camera]\nlensmodel = \"LENSMODEL_NOPE\"\nintrinsics = [1, 2, 3, 4]\n", 2, "camera.lensmodel",
               "LENSMODEL_NOPE");
}

TEST(SimSceneLoaderErrors, SamplesPerPixelMustBeAPerfectSquare) {
  expect_error("[render]\nsamples_per_pixel = 8\n", 2, "render.samples_per_pixel", "perfect square");
  expect_error("[render]\nsamples_per_pixel = 0\n", 2, "render.samples_per_pixel", "[1, 65536]");
  for (int n : {1, 4, 9, 16, 64}) {
    EXPECT_EQ(parse("[render]\nsamples_per_pixel = " + std::to_string(n) + "\n").render.samples_per_pixel, n);
  }
}

TEST(SimSceneLoaderErrors, DuplicateNames) {
  expect_error("[[object]]\nname = \"ball\"\n[[object]]\nname = \"ball\"\n", 4, "object[1].name",
               "\"ball\" a second time");
  // Default names count too: the second entry is "object1" by default.
  expect_error("[[object]]\nname = \"object1\"\n[[object]]\n", 3, "object[1].name", "\"object1\"");
  expect_error("[[light]]\nname = \"key\"\n[[light]]\nname = \"key\"\n", 4, "light[1].name", "\"key\"");
  expect_error("[[light]]\nname = \"sun\"\n[sun]\n", 2, "light[0].name", "[sun]");
}

TEST(SimSceneLoaderErrors, DegenerateShapesAndTextures) {
  expect_error("[[object]]\nwidth_m = 0\n", 2, "object[0].width_m", "> 0");
  expect_error("[[object]]\nheight_m = -1\n", 2, "object[0].height_m", "> 0");
  expect_error("[[object]]\nshape = \"sphere\"\nradius_m = 0\n", 3, "object[0].radius_m", "> 0");
  const TempDir dir;
  dir.write("tri.gltf", kTriangleGltf);
  expect_error("[[object]]\nshape = \"mesh\"\nmesh = \"tri.gltf\"\nmesh_scale = 0\n", 4, "object[0].mesh_scale", "> 0",
               dir.path());
  expect_error("[[object]]\n[object.texture]\nkind = \"apriltag\"\nid = 587\n", 4, "object[0].texture.id", "[0, 586]");
  expect_error("[[object]]\n[object.texture]\nkind = \"apriltag\"\nfamily = \"tag16h5\"\nid = 30\n", 5,
               "object[0].texture.id", "[0, 29]");
  expect_error("[[object]]\n[object.texture]\nkind = \"apriltag\"\nfamily = \"tag99h9\"\n", 4,
               "object[0].texture.family", "tag36h11");
  expect_error("[[object]]\n[object.texture]\nkind = \"apriltag\"\nsize_m = 0\n", 4, "object[0].texture.size_m", "> 0");
  expect_error("[[object]]\n[object.texture]\nkind = \"chessboard\"\nrows = 1\n", 4, "object[0].texture.rows",
               "[2, 1000]");
  expect_error("[[object]]\nmaterial = \"mirror\"\n[object.texture]\nkind = \"chessboard\"\n", 4,
               "object[0].texture.kind", "mirror");
  expect_error("[[object]]\nshape = \"sphere\"\n[object.texture]\nkind = \"chessboard\"\n", 3, "object[0].texture",
               "plane");
  // A two-tone texture sizes the plane: a size of its own would be ignored, so it is an error.
  expect_error("[[object]]\nwidth_m = 0.2\n[object.texture]\nkind = \"apriltag\"\n", 2, "object[0].width_m",
               "sets the plane");
  expect_error("[[object]]\n[object.texture]\n", 2, "object[0].texture.kind", "\"apriltag\"");
  expect_error("[[object]]\nalbedo = [0.5, 1.5, 0.5]\n", 2, "object[0].albedo[1]", "[0, 1]");
}

TEST(SimSceneLoaderErrors, NegativeLightStrengths) {
  expect_error("[[light]]\nirradiance = -1\n", 2, "light[0].irradiance", ">= 0");
  expect_error("[[light]]\nkind = \"point\"\nintensity = -0.5\n", 3, "light[0].intensity", ">= 0");
  expect_error("[[light]]\nkind = \"sphere\"\nradius_m = 0\n", 3, "light[0].radius_m", "> 0");
  expect_error("[[light]]\ncolor = [1, -1, 1]\n", 2, "light[0].color[1]", ">= 0");
  expect_error("[[light]]\ndirection = [0, 0, 0]\n", 2, "light[0].direction", "non-zero");
  expect_error("[sun]\nirradiance = -1000\n", 2, "sun.irradiance", ">= 0");
  expect_error("[sun]\nelevation_deg = 91\n", 2, "sun.elevation_deg", "[-90, 90]");
  expect_error("[environment]\nradiance = [0, 0, -1]\n", 2, "environment.radiance[2]", ">= 0");
}

TEST(SimSceneLoaderErrors, NorthMustBeHorizontalAndNonZero) {
  expect_error("[world]\nnorth = [0, 1, 0.1]\n", 2, "world.north", "horizontal");
  expect_error("[world]\nnorth = [0, 0, 0]\n", 2, "world.north", "non-zero");
  expect_error("[world]\nnorth = [0, 0, 1]\n", 2, "world.north", "horizontal");
}

TEST(SimSceneLoaderErrors, LoadNamesTheFileItCannotRead) {
  const TempDir dir;
  try {
    load_sim_scene(dir.path() / "nope.toml");
    ADD_FAILURE() << "no error";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("nope.toml"), std::string::npos) << e.what();
  }
  // Errors inside a loaded file carry its path.
  const fs::path file = dir.write("bad.toml", "[camera]\n\nfps = 0\n");
  try {
    load_sim_scene(file);
    ADD_FAILURE() << "no error";
  } catch (const SceneError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(file.string() + ":3:", 0), 0u) << e.what();
  }
}

TEST(SimSceneLoader, BuiltinMeshesNeedNoFile) {
  const SimScene scene = parse("[[object]]\nshape = \"mesh\"\nmesh = \"builtin:cube\"\n");
  ASSERT_EQ(scene.objects.size(), 1u);
  EXPECT_EQ(scene.objects[0].shape, SimObject::Shape::Mesh);
  EXPECT_EQ(scene.objects[0].mesh_builtin, "builtin:cube");
  EXPECT_TRUE(scene.objects[0].mesh_path.empty());
  expect_error("[[object]]\nshape = \"mesh\"\nmesh = \"builtin:teapot\"\n", 3, "object[0].mesh", "builtin:teapot");
}

}  // namespace
}  // namespace arpipe::sim
