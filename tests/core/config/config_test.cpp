// Config tests: defaults, every kind of error with its file/line/column, overrides from the
// command line, and the default TOML document reading back as the default Config.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include "core/config/config.h"

namespace arpipe {
namespace {

namespace fs = std::filesystem;
constexpr double kPi = std::numbers::pi;

Config default_config_from(const std::string& source) {
  Config config;
  config.file = source;
  return config;
}

// Expects a ConfigError whose message contains every fragment.
void expect_error(const std::string& text, const std::vector<std::string>& fragments,
                  const std::vector<std::string>& overrides = {}) {
  try {
    parse_config(text, "test.toml", overrides);
    ADD_FAILURE() << "expected a ConfigError for:\n" << text;
  } catch (const ConfigError& e) {
    const std::string message = e.what();
    for (const auto& fragment : fragments)
      EXPECT_NE(message.find(fragment), std::string::npos) << "'" << fragment << "' missing from: " << message;
  }
}

TEST(Config, DefaultsAreTheDocumentedOnes) {
  const Config c;
  EXPECT_EQ(c.source.type, SourceType::Replay);
  EXPECT_EQ(c.source.pacing, ReplayPacing::Timestamps);
  EXPECT_EQ(c.track.family, "tag36h11");
  ASSERT_EQ(c.track.bundle.size(), 1u);
  EXPECT_EQ(c.track.bundle[0].id, 0);
  EXPECT_EQ(c.track.bundle[0].size_m, 0.1);
  EXPECT_EQ(c.render.msaa_samples, 4);
  EXPECT_EQ(c.render.lens, LensMode::Map);
  EXPECT_EQ(c.render.lens_canvas_scale, 1.5);
  EXPECT_EQ(c.pipeline.queue_depth, 4);
  EXPECT_EQ(c.pipeline.log_level, log::Level::Info);
  // The default light direction is (0.3, -0.4, 1) made unit length.
  EXPECT_NEAR(norm(c.render.light_direction), 1.0, 1e-15);
  EXPECT_NEAR(c.render.light_direction[0] / c.render.light_direction[2], 0.3, 1e-15);
  EXPECT_NEAR(c.render.light_direction[1] / c.render.light_direction[2], -0.4, 1e-15);
}

TEST(Config, EmptyTextGivesTheDefaults) {
  EXPECT_EQ(parse_config("", "empty.toml"), default_config_from("empty.toml"));
  // An empty [sinks] names no sink (a sink's own table would turn it on: SinksAreOffUntilNamed).
  EXPECT_EQ(parse_config("# only a comment\n[track]\n[sinks]\n", "c.toml"), default_config_from("c.toml"));
}

// The defaults that do not surprise: no virtual object and no sink unless the config names them.
TEST(Config, SinksAreOffUntilNamedAndObjectsAbsentMeanNone) {
  const Config none = parse_config("", "none.toml");
  EXPECT_TRUE(none.render.objects.empty());
  EXPECT_FALSE(none.sinks.png.enabled);
  EXPECT_FALSE(none.sinks.y4m.enabled);
  EXPECT_FALSE(none.sinks.recording.enabled);
  EXPECT_FALSE(none.sinks.results.enabled);
  const Config named = parse_config("[sinks.png]\n[sinks.results]\npath = \"r.jsonl\"\n[sinks.y4m]\nenabled = false\n", "named.toml");
  EXPECT_TRUE(named.sinks.png.enabled);
  EXPECT_EQ(named.sinks.png.dir, "out/png");  // the table's keys keep their defaults
  EXPECT_TRUE(named.sinks.results.enabled);
  EXPECT_EQ(named.sinks.results.path, "r.jsonl");
  EXPECT_FALSE(named.sinks.y4m.enabled);  // named, and switched off by its own key
  EXPECT_FALSE(named.sinks.recording.enabled);
  // A --set naming a sink's key names the sink.
  EXPECT_TRUE(parse_config("", "set.toml", {"sinks.y4m.path=v.y4m"}).sinks.y4m.enabled);
}

TEST(Config, DefaultTomlReadsBackAsTheDefaultConfigAndListsEveryKey) {
  const std::string text = default_config_toml();
  EXPECT_EQ(parse_config(text, "defaults.toml"), default_config_from("defaults.toml"));
  // Every key of the schema appears with a value, so the document is the full reference.
  for (const char* line :
       {"[source]", "type = ", "path = ", "pacing = ", "loop = ", "timestamp_offset_ns = ", "camera_model = ",
        "[track]", "enabled = ", "family = ", "quad_decimate = ", "quad_sigma = ", "threads = ", "max_hamming = ",
        "min_decision_margin = ", "ambiguity_ratio = ", "max_predicted_frames = ", "search_window = ", "still_px = ", "[[track.bundle]]", "id = ", "size_m = ", "center_m = ",
        "yaw_deg = ", "[motion]", "latency_frames = ", "default_exposure_ms = ", "[render]", "light_direction = ", "light_color = ", "ambient = ", "msaa_samples = ",
        "egl_platform = ", "lens = ", "lens_canvas_scale = ", "rolling_shutter = ", "max_predicted_uncertainty_deg = ", "reuse_layer = ", "full_canvas = ", "occluder_lod_px = ", "ground_albedo = ", "bake_catcher = ", "[render.blur]", "method = ", "samples = ",
        "min_motion_px = ", "[pipeline]", "queue_depth = ", "max_frames = ", "log_level = ", "overlap_first_stage = "})
    EXPECT_NE(text.find(std::string("\n") + line), std::string::npos) << line;
  // Absent by default (no objects, no sinks), so shown commented out with the values they take
  // when the config has them: reading the text back still gives the defaults (above).
  for (const char* line : {"[[render.objects]]", "mesh = ", "position_m = ", "scale = ", "color = ", "[sinks.png]",
                           "dir = ", "every = ", "[sinks.y4m]", "[sinks.recording]", "[sinks.results]"})
    EXPECT_NE(text.find(std::string("\n# ") + line), std::string::npos) << line;
}

TEST(Config, ReadsEveryKey) {
  const std::string text = R"(
[source]
type = "replay"
path = "rec/one"
pacing = "fast"
loop = true
timestamp_offset_ns = -1500000
camera_model = "cam.cameramodel"

[track]
enabled = true
family = "tagStandard41h12"
quad_decimate = 1
quad_sigma = -0.5
threads = 2
max_hamming = 2
min_decision_margin = 35.5
ambiguity_ratio = 4.0
max_predicted_frames = 5

[[track.bundle]]
id = 7
size_m = 0.05
center_m = [0.1, -0.2, 0.0]
yaw_deg = 90

[[track.bundle]]
id = 8
size_m = 0.08
center_m = [0.3, 0.0, 0]
yaw_deg = -45.0

[render]
enabled = false
light_direction = [0, 0, 2]
light_color = [2.0, 1.5, 1.0]
ambient = [0.1, 0.1, 0.2]
msaa_samples = 2
egl_platform = "surfaceless"
lens = "undistort"
lens_canvas_scale = 2

[[render.objects]]
mesh = "builtin:pyramid"
position_m = [0.0, 0.1, 0.02]
yaw_deg = 180
scale = 0.5
color = [0.2, 0.8, 0.2]

[[render.objects]]
mesh = "assets/duck.gltf"

[sinks.png]
enabled = false
dir = "o/png"
every = 10
[sinks.y4m]
enabled = false
path = "o/v.y4m"
[sinks.recording]
enabled = true
path = "o/rec"
[sinks.results]
enabled = false
path = "o/r.jsonl"

[pipeline]
queue_depth = 8
max_frames = 1000
log_level = "debug"
)";
  const Config c = parse_config(text, "full.toml");
  EXPECT_EQ(c.file, "full.toml");
  EXPECT_EQ(c.source.path, "rec/one");
  EXPECT_EQ(c.source.pacing, ReplayPacing::Fast);
  EXPECT_TRUE(c.source.loop);
  EXPECT_EQ(c.source.timestamp_offset_ns, -1500000);
  EXPECT_EQ(c.source.camera_model, "cam.cameramodel");
  EXPECT_EQ(c.track.family, "tagStandard41h12");
  EXPECT_EQ(c.track.quad_decimate, 1.0);
  EXPECT_EQ(c.track.quad_sigma, -0.5);
  EXPECT_EQ(c.track.threads, 2);
  EXPECT_EQ(c.track.max_hamming, 2);
  EXPECT_EQ(c.track.min_decision_margin, 35.5);
  EXPECT_EQ(c.track.ambiguity_ratio, 4.0);
  EXPECT_EQ(c.track.max_predicted_frames, 5);
  ASSERT_EQ(c.track.bundle.size(), 2u);
  EXPECT_EQ(c.track.bundle[0].id, 7);
  EXPECT_EQ(c.track.bundle[0].size_m, 0.05);
  EXPECT_EQ(c.track.bundle[0].center_m, (Vec3{0.1, -0.2, 0.0}));
  // Degrees at the boundary, radians inside: 90 deg = pi/2 to rounding.
  EXPECT_NEAR(c.track.bundle[0].yaw_rad, kPi / 2, 1e-15);
  EXPECT_NEAR(c.track.bundle[1].yaw_rad, -kPi / 4, 1e-15);
  EXPECT_EQ(c.track.bundle[1].center_m, (Vec3{0.3, 0.0, 0.0}));
  EXPECT_FALSE(c.render.enabled);
  EXPECT_EQ(c.render.light_direction, (Vec3{0, 0, 1}));  // normalised
  EXPECT_EQ(c.render.light_color, (Vec3{2.0, 1.5, 1.0}));
  EXPECT_EQ(c.render.ambient, (Vec3{0.1, 0.1, 0.2}));
  EXPECT_EQ(c.render.msaa_samples, 2);
  EXPECT_EQ(c.render.egl_platform, EglPlatformRequest::Surfaceless);
  EXPECT_EQ(c.render.lens, LensMode::Undistort);
  EXPECT_EQ(c.render.lens_canvas_scale, 2.0);
  ASSERT_EQ(c.render.objects.size(), 2u);
  EXPECT_EQ(c.render.objects[0].mesh, "builtin:pyramid");
  EXPECT_EQ(c.render.objects[0].position_m, (Vec3{0.0, 0.1, 0.02}));
  EXPECT_NEAR(c.render.objects[0].yaw_rad, kPi, 1e-15);
  EXPECT_EQ(c.render.objects[0].scale, 0.5);
  EXPECT_EQ(c.render.objects[0].color, (Vec3{0.2, 0.8, 0.2}));
  SceneObject duck;
  duck.mesh = "assets/duck.gltf";
  EXPECT_EQ(c.render.objects[1], duck);  // the rest at defaults
  EXPECT_FALSE(c.sinks.png.enabled);
  EXPECT_EQ(c.sinks.png.dir, "o/png");
  EXPECT_EQ(c.sinks.png.every, 10);
  EXPECT_EQ(c.sinks.y4m.path, "o/v.y4m");
  EXPECT_FALSE(c.sinks.y4m.enabled);
  EXPECT_TRUE(c.sinks.recording.enabled);
  EXPECT_EQ(c.sinks.recording.path, "o/rec");
  EXPECT_FALSE(c.sinks.results.enabled);
  EXPECT_EQ(c.sinks.results.path, "o/r.jsonl");
  EXPECT_EQ(c.pipeline.queue_depth, 8);
  EXPECT_EQ(c.pipeline.max_frames, 1000);
  EXPECT_EQ(c.pipeline.log_level, log::Level::Debug);
}

// The live cameras' choice keys read through their name tables into the capture code's enums.
TEST(Config, LiveSourceChoicesReadIntoTheirEnums) {
  const Config defaults;
  EXPECT_EQ(defaults.source.role, StreamRole::Video);
  EXPECT_EQ(defaults.source.pixel_format, CaptureFormat::Auto);
  EXPECT_EQ(defaults.source.timestamp_meaning, BufferTimestamps::DriverFlag);
  const Config v4l2 = parse_config(
      "[source]\ntype = \"v4l2\"\npixel_format = \"MJPG\"\ntimestamp_meaning = \"start-of-exposure\"\n", "v.toml");
  EXPECT_EQ(v4l2.source.type, SourceType::V4l2);
  EXPECT_EQ(v4l2.source.pixel_format, CaptureFormat::MJPG);
  EXPECT_EQ(v4l2.source.timestamp_meaning, BufferTimestamps::StartOfExposure);
  const Config libcamera = parse_config(
      "[source]\ntype = \"libcamera\"\nrole = \"still\"\npixel_format = \"NV12\"\ntimestamp_meaning = \"end-of-frame\"\n"
      "[pipeline]\nlog_level = \"warning\"\n",
      "l.toml");
  EXPECT_EQ(libcamera.source.type, SourceType::Libcamera);
  EXPECT_EQ(libcamera.source.role, StreamRole::Still);
  EXPECT_EQ(libcamera.source.pixel_format, CaptureFormat::NV12);
  EXPECT_EQ(libcamera.source.timestamp_meaning, BufferTimestamps::EndOfFrame);
  EXPECT_EQ(libcamera.pipeline.log_level, log::Level::Warning);
}

// [source.raw] (core/config/raw_colour_config.h): empty lists keep the camera's values; counts,
// ranges and the gains' need of white_balance = "fixed" are checked where they are written.
TEST(Config, RawColourKeysReadBackAndBadOnesAreNamed) {
  const Config defaults;
  EXPECT_TRUE(defaults.source.raw.black_level.empty());
  EXPECT_TRUE(defaults.source.raw.colour_matrix.empty());
  EXPECT_EQ(defaults.source.raw.white_balance, WhiteBalanceMode::Auto);
  const Config c = parse_config(
      "[source.raw]\nblack_level = [64, 64.5, 65, 63]\nwhite_level = 1000\nwhite_balance = \"fixed\"\n"
      "gains = [1.5, 1, 2.25]\ncolour_matrix = [1.5, -0.25, -0.25, -0.125, 1.25, -0.125, 0, -0.5, 1.5]\n",
      "r.toml");
  EXPECT_EQ(c.source.raw.black_level, (std::vector<double>{64, 64.5, 65, 63}));
  EXPECT_EQ(c.source.raw.white_level, 1000);
  EXPECT_EQ(c.source.raw.white_balance, WhiteBalanceMode::Fixed);
  EXPECT_EQ(c.source.raw.gains, (Vec3{1.5, 1, 2.25}));
  EXPECT_EQ(c.source.raw.colour_matrix, (std::vector<double>{1.5, -0.25, -0.25, -0.125, 1.25, -0.125, 0, -0.5, 1.5}));
  EXPECT_EQ(parse_config("[source.raw]\nwhite_balance = \"grey-world\"\nblack_level = [16]\n", "r.toml").source.raw.black_level,
            (std::vector<double>{16}));
  expect_error("[source.raw]\nblack_level = [64, 64]\n",
               {"test.toml:2:", "source.raw.black_level: expected [], 1 or 4 raw codes, found 2 numbers"});
  expect_error("[source.raw]\nblack_level = [-1]\n", {"source.raw.black_level[0]", "found -1"});
  expect_error("[source.raw]\ncolour_matrix = [1, 0, 0]\n", {"source.raw.colour_matrix: expected [] or 9 numbers, found 3 numbers"});
  expect_error("[source.raw]\ngains = [2, 1, 2]\n", {"source.raw.gains", "white_balance = \"fixed\""});
  expect_error("[source.raw]\nwhite_balance = \"fixed\"\ngains = [0, 1, 2]\n", {"source.raw.gains", "found 0"});
  expect_error("[source.raw]\nwhite_level = 255\nblack_level = [255]\n",
               {"source.raw.black_level: expected codes below white_level (255), found 255"});
  expect_error("[source.raw]\nwhite_balance = \"daylight\"\n", {"source.raw.white_balance: expected one of \"auto\""});
}

TEST(Config, InlineArrayOfTablesIsTheSameAsArrayOfTables) {
  const Config a = parse_config("[track]\nbundle = [{id = 3, size_m = 0.2}, {id = 4}]\n", "a.toml");
  ASSERT_EQ(a.track.bundle.size(), 2u);
  EXPECT_EQ(a.track.bundle[0].id, 3);
  EXPECT_EQ(a.track.bundle[0].size_m, 0.2);
  EXPECT_EQ(a.track.bundle[1].id, 4);
  EXPECT_EQ(a.track.bundle[1].size_m, 0.1);
}

TEST(Config, EmptyObjectListMeansNothingVirtual) {
  EXPECT_TRUE(parse_config("[render]\nobjects = []\n", "e.toml").render.objects.empty());
}

TEST(Config, UnknownKeysAreErrorsWithPlaceAndAllowedKeys) {
  expect_error("[track]\nfamily = \"tag36h11\"\nfamliy = \"x\"\n",
               {"test.toml:3:1:", "track.famliy: unknown key", "allowed keys in [track]:", "family", "bundle",
                "ambiguity_ratio"});
  expect_error("\n\n[tracking]\nenabled = true\n",
               {"test.toml:3:", "tracking: unknown key", "source, track, motion, light, render, sinks, pipeline"});
  expect_error("typo = 1\n", {"test.toml:1:1:", "typo: unknown key"});
  expect_error("[sinks.png]\nenabled = true\nquality = 9\n",
               {"test.toml:3:1:", "sinks.png.quality: unknown key", "allowed keys in [sinks.png]: enabled, dir, every"});
  expect_error("[sinks.jpeg]\n", {"test.toml:1:", "sinks.jpeg: unknown key", "png, y4m, recording, results"});
  expect_error("[[track.bundle]]\nid = 1\n[[track.bundle]]\nid = 2\nsize = 0.1\n",
               {"test.toml:5:1:", "track.bundle[1].size: unknown key", "id, size_m, center_m, yaw_deg"});
  expect_error("[[render.objects]]\nyaw = 90\n",
               {"test.toml:2:1:", "render.objects[0].yaw: unknown key", "mesh, position_m, yaw_deg, scale, color"});
  // Several unknown keys: the first in the file is named.
  expect_error("[pipeline]\nzzz = 1\naaa = 2\n", {"test.toml:2:1:", "pipeline.zzz:"});
}

TEST(Config, WrongTypesSayWhatWasExpected) {
  expect_error("[pipeline]\nqueue_depth = \"4\"\n",
               {"test.toml:2:15:", "pipeline.queue_depth: expected an integer >= 1, found a string"});
  expect_error("[pipeline]\nqueue_depth = 4.0\n", {"test.toml:2:15:", "expected an integer >= 1, found a float"});
  expect_error("[source]\nloop = 1\n", {"test.toml:2:8:", "source.loop: expected a boolean", "found an integer"});
  expect_error("[track]\nquad_decimate = \"2\"\n", {"test.toml:2:", "track.quad_decimate: expected", "found a string"});
  expect_error("[source]\npath = 3\n", {"test.toml:2:8:", "source.path: expected a string, found an integer"});
  expect_error("source = 3\n", {"test.toml:1:", "source: expected a table, found an integer"});
  expect_error("[track]\nbundle = 3\n", {"test.toml:2:", "track.bundle: expected an array of tables, found an integer"});
  expect_error("[track]\nbundle = [1, 2]\n", {"test.toml:2:", "track.bundle[0]: expected a table, found an integer"});
  expect_error("[render]\nambient = [0.1, 0.1]\n",
               {"test.toml:2:11:", "render.ambient: expected an array of 3", "found 2 items"});
  expect_error("[render]\nambient = [0.1, \"x\", 0.1]\n", {"test.toml:2:", "render.ambient[1]: expected", "found a string"});
  expect_error("[render]\nambient = 0.1\n", {"test.toml:2:", "render.ambient: expected an array of 3", "found a float"});
  expect_error("[[track.bundle]]\nsize_m = nan\n", {"test.toml:2:", "track.bundle[0].size_m: expected a finite number"});
  expect_error("[pipeline]\nmax_frames = 2024-01-01\n", {"test.toml:2:", "found a date"});
}

TEST(Config, OutOfRangeValuesSayWhatWasExpected) {
  expect_error("[pipeline]\nqueue_depth = 0\n",
               {"test.toml:2:15:", "pipeline.queue_depth: expected an integer >= 1, found 0"});
  expect_error("[pipeline]\nmax_frames = -1\n", {"test.toml:2:", "expected an integer >= 0, found -1"});
  expect_error("[pipeline]\nlog_level = \"verbose\"\n",
               {"test.toml:2:13:", "pipeline.log_level: expected one of \"error\", \"warning\", \"info\", \"debug\"",
                "found \"verbose\""});
  expect_error("[render]\nmsaa_samples = 3\n", {"test.toml:2:16:", "expected one of 0, 1, 2, 4, found 3"});
  expect_error("[render]\nmsaa_samples = 8\n", {"expected one of 0, 1, 2, 4, found 8"});
  expect_error("[render]\negl_platform = \"x11\"\n", {"render.egl_platform: expected one of", "found \"x11\""});
  expect_error("[render]\nlens = \"fisheye\"\n",
               {"test.toml:2:8:", "render.lens: expected one of \"map\", \"vertex\", \"undistort\"",
                "found \"fisheye\""});
  expect_error("[render]\nlens = 1\n", {"test.toml:2:8:", "render.lens: expected one of", "found an integer"});
  expect_error("[render]\nlens_canvas_scale = 0.5\n",
               {"test.toml:2:21:", "render.lens_canvas_scale: expected a number in [1, 4], found 0.5"});
  expect_error("[render]\nlens_canvas_scale = 8\n", {"render.lens_canvas_scale: expected a number in [1, 4], found 8.0"});
  expect_error("[source]\ntype = \"gstreamer\"\n",
               {"test.toml:2:8:", "source.type: expected one of \"replay\", \"v4l2\", \"libcamera\""});
  expect_error("[source]\nbuffers = 2\n", {"test.toml:2:11:", "source.buffers: expected an integer in [4, 32], found 2"});
  expect_error("[source]\npixel_format = \"H264\"\n", {"source.pixel_format: expected one of \"auto\"", "found \"H264\""});
  expect_error("[source]\ntimestamp_meaning = \"middle\"\n",
               {"source.timestamp_meaning: expected one of \"auto\", \"start-of-exposure\", \"end-of-exposure\", \"end-of-frame\""});
  expect_error("[source]\nreconnect_min_ms = 500\nreconnect_max_ms = 100\n",
               {"test.toml:3:", "source.reconnect_max_ms: expected at least reconnect_min_ms (500), found 100"});
  expect_error("[source]\npacing = \"slow\"\n", {"source.pacing: expected one of \"timestamps\", \"fast\""});
  expect_error("[track]\nfamily = \"tag36h12\"\n",
               {"test.toml:2:10:", "track.family: expected one of", "tagCircle49h12", "tag36h10", "found \"tag36h12\""});
  expect_error("[track]\nthreads = 0\n", {"track.threads: expected an integer in [1, 64], found 0"});
  expect_error("[track]\nmax_predicted_frames = 31\n",
               {"track.max_predicted_frames: expected an integer in [0, 30], found 31"});
  expect_error("[track]\nmax_predicted_frames = -1\n",
               {"track.max_predicted_frames: expected an integer in [0, 30], found -1"});
  expect_error("[track]\nmax_hamming = 4\n", {"track.max_hamming: expected an integer in [0, 3], found 4"});
  expect_error("[track]\nquad_decimate = 0.5\n", {"track.quad_decimate: expected a number >= 1, found 0.5"});
  expect_error("[track]\nambiguity_ratio = 0.9\n", {"track.ambiguity_ratio: expected a number >= 1"});
  expect_error("[track]\nmin_decision_margin = -1\n", {"track.min_decision_margin: expected a number >= 0"});
  expect_error("[[track.bundle]]\nid = 0\nsize_m = 0\n",
               {"test.toml:3:10:", "track.bundle[0].size_m: expected a number > 0, found 0.0"});
  expect_error("[[track.bundle]]\nid = -1\n", {"track.bundle[0].id: expected an integer in [0, 586], found -1"});
  expect_error("[[track.bundle]]\nid = 4\n[[track.bundle]]\nid = 5\n[[track.bundle]]\nid = 4\n",
               {"test.toml:6:6:", "track.bundle[2].id: expected an id not used by another tag", "4"});
  expect_error("[track]\nbundle = []\n", {"test.toml:2:", "track.bundle: expected at least one tag"});
  expect_error("[[render.objects]]\nscale = 0\n", {"render.objects[0].scale: expected a number > 0"});
  expect_error("[[render.objects]]\ncolor = [1, -0.1, 0]\n", {"render.objects[0].color[1]: expected", ">= 0"});
  expect_error("[[render.objects]]\nmesh = \"\"\n", {"render.objects[0].mesh: expected"});
  expect_error("[render]\nlight_direction = [0, 0, 0]\n",
               {"test.toml:2:19:", "render.light_direction: expected a non-zero direction"});
  expect_error("[sinks.png]\nevery = 0\n", {"test.toml:2:9:", "sinks.png.every: expected an integer >= 1, found 0"});
  expect_error("[track]\nthreads = 5000000000\n", {"track.threads: expected an integer in [1, 64], found 5000000000"});
}

TEST(Config, TagIdsMustExistInTheFamily) {
  // tag16h5 has 30 codes and tag36h11 587 (AprilTag's published family sizes).
  EXPECT_EQ(parse_config("[track]\nfamily = \"tag16h5\"\n[[track.bundle]]\nid = 29\n", "a").track.bundle[0].id, 29);
  expect_error("[track]\nfamily = \"tag16h5\"\n[[track.bundle]]\nid = 30\n",
               {"test.toml:4:6:", "expected an integer in [0, 29], found 30"});
  EXPECT_EQ(parse_config("[[track.bundle]]\nid = 586\n", "a").track.bundle[0].id, 586);
  expect_error("[[track.bundle]]\nid = 587\n", {"expected an integer in [0, 586], found 587"});
}

TEST(Config, SyntaxErrorsNameFileLineAndColumn) {
  expect_error("[pipeline]\nqueue_depth = = 4\n", {"test.toml:2:", "TOML syntax error"});
  expect_error("[pipeline\n", {"test.toml:1:", "TOML syntax error"});
  expect_error("[source]\npath = \"unterminated\n", {"test.toml:2:", "TOML syntax error"});
  expect_error("a = 1\na = 2\n", {"test.toml:2:", "TOML syntax error"});
}

TEST(Config, LoadConfigReadsAFileAndNamesItInErrors) {
  const fs::path dir = fs::path(ARPIPE_BINARY_DIR) / "test_tmp" / "config";
  fs::create_directories(dir);
  const fs::path good = dir / "good.toml";
  std::ofstream(good) << "[pipeline]\nqueue_depth = 2\n";
  const Config c = load_config(good);
  EXPECT_EQ(c.file, good);
  EXPECT_EQ(c.pipeline.queue_depth, 2);

  const fs::path bad = dir / "bad.toml";
  std::ofstream(bad) << "[pipeline]\n\nqueue_depth = -3\n";
  try {
    load_config(bad);
    ADD_FAILURE() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find(bad.string() + ":3:15:"), std::string::npos) << e.what();
  }
  const fs::path missing = dir / "missing.toml";
  try {
    load_config(missing);
    ADD_FAILURE() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find(missing.string()), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("No such file"), std::string::npos) << e.what();
  }
  const fs::path syntax = dir / "syntax.toml";
  std::ofstream(syntax) << "[source]\npath = 'a'\nloop = yes\n";
  try {
    load_config(syntax);
    ADD_FAILURE() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find(syntax.string() + ":3:"), std::string::npos) << e.what();
  }
}

TEST(Config, OverridesReplaceKeysBeforeValidation) {
  const std::string file = "[pipeline]\nqueue_depth = 0\n[[render.objects]]\nscale = 2.0\n[[render.objects]]\n";
  // queue_depth = 0 is invalid in the file, but the override replaces it before validation.
  const Config c = parse_config(file, "o.toml",
                                {"pipeline.queue_depth=3", "track.family = \"tag25h9\"", "source.pacing=fast",
                                 "render.objects.1.scale=0.25", "render.objects.0.position_m=[1, 2, 3]",
                                 "sinks.png.dir=out/run1", "render.ambient=[0.5, 0.5, 0.5]", "render.lens=vertex"});
  EXPECT_EQ(c.pipeline.queue_depth, 3);
  EXPECT_EQ(c.track.family, "tag25h9");
  EXPECT_EQ(c.source.pacing, ReplayPacing::Fast);  // a bare word is a string
  ASSERT_EQ(c.render.objects.size(), 2u);
  EXPECT_EQ(c.render.objects[0].scale, 2.0);
  EXPECT_EQ(c.render.objects[0].position_m, (Vec3{1, 2, 3}));
  EXPECT_EQ(c.render.objects[1].scale, 0.25);
  EXPECT_EQ(c.sinks.png.dir, "out/run1");
  EXPECT_EQ(c.render.ambient, (Vec3{0.5, 0.5, 0.5}));
  EXPECT_EQ(c.render.lens, LensMode::Vertex);
  // Later overrides win; an inline table replaces the whole table.
  const Config d = parse_config("[source]\npath = \"a\"\nloop = true\n", "o.toml",
                                {"pipeline.max_frames=5", "pipeline.max_frames=6", "source={path=\"b\"}"});
  EXPECT_EQ(d.pipeline.max_frames, 6);
  EXPECT_EQ(d.source.path, "b");
  EXPECT_FALSE(d.source.loop);
  // A whole array of tables from the command line.
  const Config e = parse_config("", "o.toml", {"track.bundle=[{id=5, size_m=0.2}, {id=6}]"});
  ASSERT_EQ(e.track.bundle.size(), 2u);
  EXPECT_EQ(e.track.bundle[0].id, 5);
  EXPECT_EQ(e.track.bundle[1].id, 6);
}

TEST(Config, MotionKeysHaveTheirDefaultsAndReadBack) {
  const Config d;
  EXPECT_TRUE(d.motion.enabled);
  EXPECT_EQ(d.motion.latency_frames, 0);
  EXPECT_EQ(d.motion.default_exposure_ns, 10'000'000);
  const Config c = parse_config("[motion]\nenabled = false\nlatency_frames = 1\ndefault_exposure_ms = 2.5\n", "m.toml");
  EXPECT_FALSE(c.motion.enabled);
  EXPECT_EQ(c.motion.latency_frames, 1);
  EXPECT_EQ(c.motion.default_exposure_ns, 2'500'000);
  // Integers are numbers too, and the override path is validated like the file.
  EXPECT_EQ(parse_config("[motion]\ndefault_exposure_ms = 4\n", "m.toml").motion.default_exposure_ns, 4'000'000);
  EXPECT_EQ(parse_config("", "m.toml", {"motion.latency_frames=1"}).motion.latency_frames, 1);
}

TEST(Config, MotionValuesOutOfRangeAreRefusedNamingFileAndKey) {
  expect_error("[motion]\nlatency_frames = 2\n",
               {"test.toml:2:", "motion.latency_frames: expected 0 (extrapolate, no delay) or 1", "found 2"});
  expect_error("[motion]\nlatency_frames = -1\n", {"test.toml:2:", "motion.latency_frames:", "found -1"});
  expect_error("[motion]\nlatency_frames = 1.0\n", {"motion.latency_frames: expected an integer", "found a float"});
  expect_error("[motion]\ndefault_exposure_ms = 0\n",
               {"test.toml:2:", "motion.default_exposure_ms: expected a number in (0, 1000] (ms), found 0.0"});
  expect_error("[motion]\ndefault_exposure_ms = -3\n", {"motion.default_exposure_ms:", "found -3.0"});
  expect_error("[motion]\ndefault_exposure_ms = 1500\n", {"motion.default_exposure_ms:", "found 1500.0"});
  expect_error("[motion]\ndefault_exposure_ms = \"8\"\n", {"motion.default_exposure_ms:", "found a string"});
  expect_error("[motion]\nenabled = 1\n", {"motion.enabled: expected a boolean"});
  expect_error("[motion]\nlatency = 1\n",
               {"test.toml:2:1:", "motion.latency: unknown key", "enabled, latency_frames, default_exposure_ms"});
  expect_error("", {"override 'motion.latency_frames=3'", "found 3"}, {"motion.latency_frames=3"});
}

TEST(Config, BadOverridesAreErrorsNamingTheOverride) {
  expect_error("", {"override 'pipeline.queue_depth'", "expected section.key=value"}, {"pipeline.queue_depth"});
  expect_error("", {"override 'pipeline..x=1'", "not a dotted key"}, {"pipeline..x=1"});
  expect_error("", {"override '=1'", "not a dotted key"}, {"=1"});
  expect_error("", {"override 'render.ambient=[1,2'", "not valid TOML"}, {"render.ambient=[1,2"});
  expect_error("", {"override 'pipeline.queue_depth=0'", "pipeline.queue_depth: expected an integer >= 1, found 0"},
               {"pipeline.queue_depth=0"});
  expect_error("", {"override 'pipeline.queue_depht=2'", "pipeline.queue_depht: unknown key", "queue_depth"},
               {"pipeline.queue_depht=2"});
  expect_error("", {"override 'pipline.queue_depth=2'", "pipline: unknown key"}, {"pipline.queue_depth=2"});
  expect_error("", {"override 'pipeline.queue_depth=four'", "expected an integer >= 1, found a string"},
               {"pipeline.queue_depth=four"});
  expect_error("[[render.objects]]\n", {"override 'render.objects.3.scale=1'", "not an index"},
               {"render.objects.3.scale=1"});
  expect_error("", {"override 'track.bundle.0.size_m=0.2'", "'track.bundle' is not in the file", "track.bundle=[{"},
               {"track.bundle.0.size_m=0.2"});
  expect_error("[source]\npath = \"x\"\n", {"override 'source.path.deeper=1'", "'source.path' is a string, not a table"},
               {"source.path.deeper=1"});
  expect_error("", {"override 'render.lens=warp'", "render.lens: expected one of \"map\", \"vertex\", \"undistort\"",
                    "found \"warp\""},
               {"render.lens=warp"});
}

}  // namespace
}  // namespace arpipe

namespace arpipe {
namespace {

TEST(Config, FootprintAndReuseKeysHaveTheirDefaultsAndReadBack) {
  const Config d;
  EXPECT_TRUE(d.render.reuse_layer);   // a still scene hands its layer on
  EXPECT_FALSE(d.render.full_canvas);  // every pass inside the footprint
  const Config c = parse_config("[render]\nreuse_layer = false\nfull_canvas = true\n", "f.toml");
  EXPECT_FALSE(c.render.reuse_layer);
  EXPECT_TRUE(c.render.full_canvas);
  EXPECT_THROW(parse_config("[render]\nfull_canvas = 1\n", "f.toml"), ConfigError);
}

TEST(Config, BlurKeysHaveTheirDefaultsAndReadBack) {
  const Config d;
  EXPECT_EQ(d.render.blur.method, BlurMethod::IntraframeWarp);
  EXPECT_EQ(d.render.blur.samples, 0);
  EXPECT_EQ(d.render.blur.min_motion_px, 0.5);
  EXPECT_TRUE(d.render.rolling_shutter);
  EXPECT_EQ(d.render.max_predicted_uncertainty_deg, 5.0);
  const Config c = parse_config(
      "[render]\nrolling_shutter = false\nmax_predicted_uncertainty_deg = 12\n[render.blur]\nmethod = \"velocity\"\nsamples = 16\nmin_motion_px = 2\n", "b.toml");
  EXPECT_FALSE(c.render.rolling_shutter);
  EXPECT_EQ(c.render.max_predicted_uncertainty_deg, 12.0);
  EXPECT_EQ(c.render.blur.method, BlurMethod::Velocity);
  EXPECT_EQ(c.render.blur.samples, 16);
  EXPECT_EQ(c.render.blur.min_motion_px, 2.0);
  EXPECT_EQ(parse_config("", "b.toml", {"render.blur.method=accumulate"}).render.blur.method, BlurMethod::Accumulate);
  // The old name of intraframe-warp (seed 000's method) is still read; the new name is written.
  EXPECT_EQ(parse_config("[render.blur]\nmethod = \"seed\"\n", "b.toml").render.blur.method, BlurMethod::IntraframeWarp);
  EXPECT_EQ(parse_config("", "b.toml", {"render.blur.method=seed"}).render.blur.method, BlurMethod::IntraframeWarp);
  EXPECT_EQ(blur_method_name(BlurMethod::IntraframeWarp), "intraframe-warp");
}

TEST(Config, BlurValuesOutOfRangeAreRefusedNamingFileAndKey) {
  expect_error("[render.blur]\nmethod = \"fast\"\n",
               {"test.toml:2:", "render.blur.method: expected one of \"off\", \"accumulate\", \"intraframe-warp\", \"velocity\""});
  expect_error("[render.blur]\nsamples = -1\n", {"test.toml:2:", "render.blur.samples:", "found -1"});
  expect_error("[render.blur]\nsamples = 2000\n", {"render.blur.samples:", "found 2000"});
  expect_error("[render.blur]\nmin_motion_px = -0.5\n", {"render.blur.min_motion_px:", "found -0.5"});
  expect_error("[render.blur]\nwidth = 3\n", {"render.blur.width: unknown key"});
  expect_error("[render]\nmax_predicted_uncertainty_deg = -1\n",
               {"test.toml:2:", "render.max_predicted_uncertainty_deg: expected a number in [0, 180] (degrees)"});
}

TEST(Config, EnvironmentAndPrtKeysHaveTheirDefaultsAndReadBack) {
  const Config d;
  EXPECT_EQ(d.light.environment.layout, EnvironmentLayout::Equirectangular);
  EXPECT_EQ(d.light.environment.scale, 1.0);
  EXPECT_EQ(d.light.environment.window, ShWindow::None);
  EXPECT_EQ(d.render.prt.samples, 32);
  EXPECT_EQ(d.render.prt.bands, 3);
  EXPECT_EQ(SceneObject{}.prt, ObjectPrt::Shadowed);
  const Config c = parse_config(
      "[light]\nsource = \"environment\"\n[light.environment]\nfile = \"probe.exr\"\nlayout = \"angular\"\n"
      "yaw_deg = 90\nscale = 2.5\nwindow = \"hanning\"\n[render.prt]\nsamples = 40\nbands = 5\ncache_dir = \"c\"\n"
      "[[render.objects]]\nmesh = \"builtin:cup\"\nprt = \"interreflected\"\n",
      "e.toml");
  EXPECT_EQ(c.light.source, LightSource::Environment);
  EXPECT_EQ(c.light.environment.file, fs::path("probe.exr"));
  EXPECT_EQ(c.light.environment.layout, EnvironmentLayout::AngularMap);
  EXPECT_NEAR(c.light.environment.yaw_rad, kPi / 2, 1e-15);
  EXPECT_EQ(c.light.environment.scale, 2.5);
  EXPECT_EQ(c.light.environment.window, ShWindow::Hanning);
  EXPECT_EQ(c.render.prt.samples, 40);
  EXPECT_EQ(c.render.prt.bands, 5);
  EXPECT_EQ(c.render.prt.cache_dir, fs::path("c"));
  EXPECT_EQ(c.render.objects.at(0).prt, ObjectPrt::Interreflected);
}

TEST(Config, ProbeKeysReadThroughTheirNameTablesWithTheSeedsOldNames) {
  const Config d;
  EXPECT_EQ(d.light.probe.kind, ProbeKind::Mirror);
  EXPECT_EQ(d.light.probe.method, ProbeMethod::Auto);
  EXPECT_EQ(d.light.source, LightSource::Fixed);
  const Config c = parse_config("[light]\nsource = \"probe\"\n[light.probe]\nkind = \"diffuse\"\nmethod = \"brightest-sphere\"\n", "p.toml");
  EXPECT_EQ(c.light.source, LightSource::Probe);
  EXPECT_EQ(c.light.probe.kind, ProbeKind::Diffuse);
  EXPECT_EQ(c.light.probe.method, ProbeMethod::BrightestSphere);
  // seeds 001/004's method under its old names; the new names are written.
  EXPECT_EQ(parse_config("[light.probe]\nmethod = \"seed-image\"\n", "p.toml").light.probe.method, ProbeMethod::BrightestImage);
  EXPECT_EQ(parse_config("", "p.toml", {"light.probe.method=seed-sphere"}).light.probe.method, ProbeMethod::BrightestSphere);
  EXPECT_EQ(probe_method_name(ProbeMethod::BrightestImage), "brightest-image");
  expect_error("[light.probe]\nmethod = \"median\"\n",
               {"test.toml:2:", "light.probe.method: expected one of \"auto\", \"environment\", \"fit\", \"brightest-image\", "
                                "\"brightest-sphere\"", "found \"median\""});
  expect_error("[light.probe]\nkind = \"glass\"\n", {"light.probe.kind: expected one of \"mirror\", \"diffuse\""});
  expect_error("[light.environment]\nwindow = \"hamming\"\n",
               {"light.environment.window: expected one of \"none\", \"hanning\", \"lanczos\""});
}

// --defaults names each choice's old names next to its rule.
TEST(Config, DefaultsListTheOldNamesOfRenamedChoices) {
  const std::string text = default_config_toml();
  EXPECT_NE(text.find("method = \"intraframe-warp\""), std::string::npos) << text;
  EXPECT_NE(text.find("\"seed\" (= \"intraframe-warp\")"), std::string::npos) << text;
  EXPECT_NE(text.find("\"seed-image\" (= \"brightest-image\"), \"seed-sphere\" (= \"brightest-sphere\")"), std::string::npos)
      << text;
}

TEST(Config, EnvironmentAndPrtValuesOutOfRangeAreRefusedNamingFileAndKey) {
  expect_error("[light]\nsource = \"environment\"\n",
               {"test.toml:2:", "light.source:", "light.environment.file to be set"});
  expect_error("[light.environment]\nlayout = \"fisheye\"\n",
               {"test.toml:2:", "light.environment.layout: expected one of \"angular\", \"mirror-ball\", \"equirect\", \"cube-cross\""});
  expect_error("[light.environment]\nscale = 0\n", {"light.environment.scale:", "found 0"});
  expect_error("[render.prt]\nsamples = 1\n", {"render.prt.samples:", "found 1"});
  expect_error("[render.prt]\nbands = 9\n", {"render.prt.bands:", "found 9"});
  expect_error("[[render.objects]]\nprt = \"ambient\"\n", {"render.objects[0].prt:"});
  expect_error("[[render.objects]]\nspecular = 1.5\n", {"render.objects[0].specular: expected a number in [0, 1]"});
}

}  // namespace
}  // namespace arpipe

namespace arpipe {
namespace {

TEST(Config, LightResponseIsParsedOnceByTheCameraResponseRule) {
  EXPECT_EQ(Config{}.light.response, CameraResponse::srgb());
  EXPECT_EQ(parse_config("[light]\nresponse = \"linear\"\n", "r.toml").light.response, CameraResponse::linear());
  const CameraResponse g = parse_config("[light]\nresponse = \"gamma:2.2\"\n", "r.toml").light.response;
  EXPECT_EQ(g.kind(), CameraResponse::Kind::Gamma);
  EXPECT_EQ(g.gamma_value(), 2.2);
  expect_error("[light]\nresponse = \"gamma:0\"\n",
               {"test.toml:2:12:", "light.response: expected \"srgb\", \"linear\" or \"gamma:<g>\" with g > 0", "found \"gamma:0\""});
  expect_error("[light]\nresponse = \"log\"\n", {"light.response: expected", "found \"log\""});
  // --defaults prints the typed value by its name, and reads back as the same value.
  EXPECT_NE(default_config_toml().find("\nresponse = \"srgb\""), std::string::npos);
}

}  // namespace
}  // namespace arpipe

namespace arpipe {
namespace {

TEST(Config, PanoramaTrackAndLightNeedTheirCounterparts) {
  // A head-pose track gives the orientation over time: a sweep or pitch beside it is refused.
  expect_error("[source]\ntype = \"panorama\"\n[source.panorama]\nfile = \"p.png\"\n[source.panorama.view]\n"
               "track = \"head.csv\"\nyaw_deg_per_s = 12.0\n",
               {"test.toml", "source.panorama.view.yaw_deg_per_s", "expected 0 with a track"});
  expect_error("[source]\ntype = \"panorama\"\n[source.panorama]\nfile = \"p.png\"\n[source.panorama.view]\n"
               "track = \"head.csv\"\npitch_deg = 10.0\n",
               {"source.panorama.view.pitch_deg", "expected 0 with a track"});
  const Config tracked = parse_config(
      "[source]\ntype = \"panorama\"\n[source.panorama]\nfile = \"p.png\"\n[source.panorama.view]\ntrack = \"head.csv\"\n"
      "yaw_deg = 30.0\n", "test.toml");
  EXPECT_EQ(tracked.source.panorama.view.track, "head.csv");
  // The panorama's light needs a panorama source.
  expect_error("[light]\nsource = \"panorama\"\n", {"light", "needs source.type = \"panorama\""});
  const Config lit = parse_config(
      "[source]\ntype = \"panorama\"\n[source.panorama]\nfile = \"p.png\"\n[light]\nsource = \"panorama\"\n"
      "[light.panorama]\ndirect_light_from_render = false\n", "test.toml");
  EXPECT_EQ(lit.light.source, LightSource::Panorama);
  EXPECT_FALSE(lit.light.panorama.direct_light_from_render);
}

TEST(Config, PanoramaViewpointsNeedADwellAndTheirProxiesAViewpointThatExists) {
  const std::string two = "[source]\ntype = \"panorama\"\n[source.panorama]\nfile = \"a.png\"\n"
                          "[[source.panorama.viewpoints]]\nfile = \"b.png\"\nposition_m = [1.0, 0.0, 0.0]\n";
  expect_error(two, {"source.panorama.viewpoints", "dwell_s > 0"});
  const Config ok = parse_config(two + "[source.panorama.view]\ndwell_s = 60.0\n[[render.proxies]]\nviewpoint = 1\n", "test.toml");
  ASSERT_EQ(ok.source.panorama.viewpoint_count(), 2u);
  EXPECT_EQ(ok.source.panorama.viewpoint(1).file, "b.png");
  EXPECT_EQ(ok.source.panorama.viewpoint(1).position_m, (Vec3{1, 0, 0}));
  EXPECT_EQ(ok.render.proxies[0].viewpoint, 1);
  expect_error(two + "[source.panorama.view]\ndwell_s = 60.0\n[[render.proxies]]\nviewpoint = 2\n",
               {"render.proxies[0].viewpoint", "-1 or a viewpoint in [0, 1]", "found 2"});
  expect_error("[[render.proxies]]\nviewpoint = 0\n", {"render.proxies[0].viewpoint", "viewpoints belong to a panorama source"});
  expect_error("[source]\ntype = \"panorama\"\n[source.panorama]\nfile = \"a.png\"\n[[source.panorama.viewpoints]]\n"
               "position_m = [1.0, 0.0, 0.0]\n[source.panorama.view]\ndwell_s = 1.0\n",
               {"source.panorama.viewpoints[0].file", "expected the viewpoint's panorama file"});
}

TEST(Config, AStereoPanoramaNamesItsLayoutRigAndOutput) {
  const Config stereo = parse_config(
      "[source]\ntype = \"panorama\"\n[source.panorama]\nfile = \"p.png\"\nlayout = \"equirect-lr\"\nipd_m = 0.063\n"
      "pole_merge_from_deg = 50.0\npole_merge_to_deg = 80.0\n[source.panorama.view]\nstereo_output = \"frames\"\n",
      "test.toml");
  const PanoramaConfig& p = stereo.source.panorama;
  EXPECT_EQ(p.layout, PanoramaLayout::EquirectLeftRight);
  EXPECT_EQ(p.view.stereo_output, StereoOutput::Frames);
  EXPECT_EQ(p.ods_rig().ipd_m, 0.063);
  EXPECT_NEAR(p.ods_rig().pole_merge_from_rad, 50 * std::numbers::pi / 180, 1e-15);
  EXPECT_NEAR(p.ods_rig().pole_merge_to_rad, 80 * std::numbers::pi / 180, 1e-15);
  // The defaults: the layout from the file, 64 mm apart, merged from 60 to 75 degrees, packed top/bottom.
  const PanoramaConfig defaults;
  EXPECT_EQ(defaults.layout, PanoramaLayout::Auto);
  EXPECT_EQ(defaults.view.stereo_output, StereoOutput::TopBottom);
  EXPECT_EQ(defaults.ods_rig(), OdsRig{});
  expect_error("[source.panorama]\npole_merge_from_deg = 70.0\npole_merge_to_deg = 65.0\n",
               {"source.panorama.pole_merge_to_deg", "at least pole_merge_from_deg (70)", "65"});
  expect_error("[source.panorama]\nlayout = \"cubemap\"\n", {"source.panorama.layout", "equirect-tb"});
  expect_error("[source.panorama]\nipd_m = 0.0\n", {"source.panorama.ipd_m"});
}

}  // namespace
}  // namespace arpipe
