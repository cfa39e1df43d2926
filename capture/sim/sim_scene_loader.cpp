// Scene files through the project's TOML section reader (core/config/toml_section.h): one walk over
// the tree reads every key with its default, checks its type and range, rejects unknown keys, and
// checks that the scene as a whole can be simulated.
#include "capture/sim/sim_scene_loader.h"

#include <apriltag/apriltag.h>
#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <numbers>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <system_error>

#include <unistd.h>

#include "capture/sim/sim_textures.h"
#include "capture/sim/simulator.h"
#include "core/config/regular_file.h"
#include "core/config/text_file.h"
#include "core/config/toml_section.h"
#include "core/image/image_header.h"
#include "core/scene/asset_error.h"
#include "core/scene/builtin_meshes.h"
#include "core/scene/gltf_loader.h"
#include "core/track/tag_family.h"

namespace arpipe::sim {

namespace {

namespace fs = std::filesystem;

constexpr double kRadiansPerDegree = std::numbers::pi / 180.0;
constexpr double kNsPerMs = 1e6;
// Counts a scene file may declare: far above any real scene, low enough that a small file cannot
// make the simulator build thousands of Embree objects or walk millions of keyframes.
constexpr size_t kMaxObjects = 1000;
constexpr size_t kMaxLights = 100;
constexpr size_t kMaxKeyframes = 100000;
// An object's pose track: a key per frame of a five-minute video at 30 fps is 9000.
constexpr size_t kMaxObjectKeyframes = 10000;
constexpr size_t kMaxListNumbers = 10000;  // exposure cycles, intrinsics (a splined model has a few thousand)
// `up` closer than this (sine of the angle) to the viewing direction leaves the image's roll
// undefined for practical purposes (0.06 degrees).
constexpr double kMinUpAngleSine = 1e-3;
// Times add up (start, offset, exposure, readout) in int64 ns, which holds +-9.2e12 ms.
constexpr double kMaxAbsMs = 1e12;  // 31 years

const NumberRange kPositive = NumberRange::above(0);
const NumberRange kNonNegative = NumberRange::at_least(0);
const NumberRange kUnitInterval = NumberRange::closed(0, 1);
// The largest circle of confusion: a 33 x 33 kernel, a few seconds a 640 x 480 frame.
constexpr double kMaxDefocusPx = 32;

std::string show(const Vec3& v) { return fmt::format("[{}, {}, {}]", v[0], v[1], v[2]); }

int64_t ms_to_ns(double ms) { return std::llround(std::clamp(ms, -kMaxAbsMs, kMaxAbsMs) * kNsPerMs); }

// ---- Reads the section reader has no word for ----------------------------------------------------

// A key that makes no sense with the rest of the table.
void forbid(const TomlSection& s, std::string_view k, const std::string& why) {
  if (s.has(k)) s.fail_with(k, fmt::format("not allowed here: {}", why));
}

// [[k]] entries (or an inline array of inline tables), named "k[0]", "k[1]"...; at most max_count.
std::vector<TomlSection> table_array(const TomlSection& s, std::string_view k, size_t max_count) {
  if (const toml::node* n = s.node(k); n != nullptr && !n->is_array())
    s.fail(k, fmt::format("an array of tables ([[{}]])", k), std::string(toml_type_phrase(*n)));
  return s.sections(k, max_count);
}

// Degrees in the file, radians inside; an absent key keeps its default bit for bit.
double degrees(const TomlSection& s, std::string_view k, double fallback_rad, const NumberRange& range = {}) {
  if (!s.has(k)) {
    s.allow(k);
    return fallback_rad;
  }
  return s.number(k, 0, range) * kRadiansPerDegree;
}

// Milliseconds in the file, nanoseconds inside, within +-kMaxAbsMs so that sums stay in int64.
int64_t milliseconds(const TomlSection& s, std::string_view k, int64_t fallback_ns, const NumberRange& range = {}) {
  if (!s.has(k)) {
    s.allow(k);
    return fallback_ns;
  }
  const double ms = s.number(k, 0, range);
  if (std::abs(ms) > kMaxAbsMs)
    s.fail(k, fmt::format("{}, within +-{:g} ms", range.phrase(), kMaxAbsMs), fmt::format("{}", ms));
  return ms_to_ns(ms);
}

// A file named relative to the scene file's directory; it must exist and be a readable regular file.
fs::path asset_file(const TomlSection& s, std::string_view k, std::string_view what) {
  const std::string text = s.string(k, "");
  if (text.empty()) s.fail(k, fmt::format("the name of {}", what), s.has(k) ? "an empty string" : "nothing");
  const fs::path path = s.path(k, {}).lexically_normal();
  const auto fail = [&](const std::string& why) {
    s.fail_with(k, fmt::format("expected {}, found \"{}\" ({}): {}", what, text, path.string(), why));
  };
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (ec && ec != std::errc::no_such_file_or_directory) fail(ec.message());  // a symlink loop, no permission
  if (!fs::exists(status)) fail("no such file");
  if (fs::is_directory(status)) fail("a directory");
  // Regular files only (no FIFO to block on, no device), and not empty.
  try {
    const int fd = open_regular_file(path, what);
    char first = 0;
    const ssize_t n = ::read(fd, &first, 1);
    ::close(fd);
    if (n != 1) fail(fmt::format("cannot read it: {}", n == 0 ? "it is empty" : std::strerror(errno)));
  } catch (const FileAccessError& e) {
    fail(e.reason());
  }
  return path;
}

Vec3 unit_direction(const TomlSection& s, std::string_view k, const Vec3& fallback) {
  const Vec3 v = s.vec3(k, fallback);
  const double length = norm(v);
  if (length == 0) s.fail(k, "a non-zero direction", show(v));
  return std::abs(length - 1) <= 1e-15 ? v : normalized(v);  // a unit vector stays bit for bit
}

// ---- [world] -----------------------------------------------------------------------------------

Vec3 read_world(const TomlSection& s) {
  const Vec3 north = s.vec3("north", {0, 1, 0});
  const double length = norm(north);
  if (length == 0) s.fail("north", "a non-zero horizontal direction [x, y, 0]", show(north));
  if (std::abs(north[2]) > 1e-12 * length)
    s.fail("north", "a horizontal direction [x, y, 0] (world z is up)", fmt::format("{} (z is not 0)", show(north)));
  const Vec3 horizontal{north[0], north[1], 0};
  return std::abs(length - 1) <= 1e-15 ? horizontal : normalized(horizontal);
}

// ---- [camera] ----------------------------------------------------------------------------------

CameraModel read_camera_model(const TomlSection& s) {
  const std::vector<std::string_view> inline_keys{"lensmodel", "intrinsics", "width", "height"};
  if (s.has("model")) {
    for (const auto k : inline_keys)
      forbid(s, k, "the lens comes from camera.model; give either model or lensmodel/intrinsics/width/height");
    const fs::path path = asset_file(s, "model", "an mrcal .cameramodel file");
    try {
      return CameraModel::load(path);
    } catch (const CameraModelError& e) {
      s.fail_with("model", fmt::format("expected a valid mrcal .cameramodel file, found one that is not ({}): {}",
                                       path.string(), e.what()));
    }
  }
  const int width = s.integer_as<int>("width", 640, IntRange{1, 65535});
  const int height = s.integer_as<int>("height", 480, IntRange{1, 65535});
  const std::string lensmodel = s.string("lensmodel", "LENSMODEL_PINHOLE");
  if (lensmodel != "LENSMODEL_PINHOLE" && !s.has("intrinsics"))
    s.fail("intrinsics", fmt::format("the intrinsics of {} (fx, fy, cx, cy, then its distortion)", lensmodel),
           "nothing");
  const std::vector<double> intrinsics =
      s.number_list("intrinsics", {500, 500, (width - 1) / 2.0, (height - 1) / 2.0}, {}, kMaxListNumbers);
  try {
    return CameraModel(lensmodel, intrinsics, width, height);
  } catch (const CameraModelError& e) {
    const bool bad_name = std::string_view(e.what()).find("unknown lens model") != std::string_view::npos;
    s.fail_with(bad_name || !s.has("intrinsics") ? "lensmodel" : "intrinsics",
                fmt::format("expected a valid mrcal lens model and intrinsics, found: {}", e.what()));
  }
}

// "srgb", "linear" or "gamma:<g>" with g > 0, as CameraResponse reads it.
std::optional<CameraResponse> response_curve(std::string_view text) {
  try {
    return CameraResponse::parse(text, "camera.sensor.response");
  } catch (const std::invalid_argument&) {
    return std::nullopt;
  }
}

SimCamera read_camera(const TomlSection& s) {
  SimCamera camera;
  if (s.has("model") || s.has("lensmodel") || s.has("intrinsics") || s.has("width") || s.has("height"))
    camera.model = read_camera_model(s);

  camera.pixel_format = s.parsed<PixelFormat>("pixel_format", camera.pixel_format, pixel_format_from_name,
                                              "one of \"GREY\", \"RGB24\", \"YUYV\", \"NV12\" or a Bayer format "
                                              "(SRGGB, SBGGR, SGRBG or SGBRG with 8, 10, 12, 16, 10P or 12P: \"SRGGB10P\")");
  if (const auto stereo = s.section("stereo")) {
    SimStereo& out = camera.stereo;
    out.enabled = true;
    if (camera.model.lensmodel() != "LENSMODEL_LONLAT")
      stereo->fail_with("layout", fmt::format("expected a LENSMODEL_LONLAT camera for an omnidirectional-stereo pair, found {}",
                                              camera.model.lensmodel()));
    const std::string layout = stereo->string("layout", "tb");
    if (layout != "tb" && layout != "lr") stereo->fail("layout", "\"tb\" (left eye on top) or \"lr\" (left eye on the left)", fmt::format("\"{}\"", layout));
    out.top_bottom = layout == "tb";
    out.rig.ipd_m = stereo->number("ipd_m", out.rig.ipd_m, NumberRange::open_closed(0, 1));
    out.rig.pole_merge_from_rad = degrees(*stereo, "pole_merge_from_deg", out.rig.pole_merge_from_rad, NumberRange::closed(0, 90));
    out.rig.pole_merge_to_rad = degrees(*stereo, "pole_merge_to_deg", out.rig.pole_merge_to_rad, NumberRange::closed(0, 90));
    if (out.rig.pole_merge_to_rad < out.rig.pole_merge_from_rad)
      stereo->fail("pole_merge_to_deg", "at least pole_merge_from_deg", fmt::format("{:g}", out.rig.pole_merge_to_rad / kRadiansPerDegree));
  }
  const std::string_view format = pixel_format_name(camera.pixel_format);
  if (const auto problem = check_image_size(camera.pixel_format, camera.frame_width(), camera.frame_height())) {
    const std::string_view k = s.has("pixel_format") ? "pixel_format" : s.has("model") ? "model" : "width";
    s.fail_with(k, fmt::format("expected an image size that {} can hold, found {}x{}: {}", format, camera.model.width(),
                               camera.model.height(), *problem));
  }
  if (camera.frame_width() > kMaxFrameSide || camera.frame_height() > kMaxFrameSide ||
      int64_t{camera.frame_width()} * camera.frame_height() > kMaxFramePixels) {
    const std::string_view k = s.has("model") ? "model" : camera.model.width() > kMaxFrameSide || !s.has("height") ? "width" : "height";
    s.fail_with(k, fmt::format("expected a simulated frame of at most {} pixels a side and {} pixels in all (rendering "
                               "holds about 80 bytes a pixel), found {}x{}",
                               kMaxFrameSide, kMaxFramePixels, camera.model.width(), camera.model.height()));
  }

  camera.fps =
      s.number("fps", camera.fps, NumberRange::rule([](double v) { return v > 0 && v <= 1e6; }, "(0, 1000000]"));
  const int64_t interval_ns = std::llround(1e9 / camera.fps);
  const std::string interval =
      fmt::format("the frame interval {:.6g} ms (1 / fps {})", interval_ns / kNsPerMs, camera.fps);
  const auto check_within_interval = [&](const toml::node& n, const std::string& dotted, int64_t ns) {
    if (ns <= 0) s.fail_at(n, dotted, "an exposure of at least 1 ns", fmt::format("{} ns after rounding", ns));
    if (ns > interval_ns)
      s.fail_at(n, dotted, fmt::format("no more than {}", interval), fmt::format("{:.6g} ms", ns / kNsPerMs));
  };

  if (const toml::node* n = s.node("exposure_ms")) {
    camera.exposure_ns.clear();
    if (n->is_array()) {
      const std::vector<double> list = s.number_list("exposure_ms", {}, kPositive, kMaxListNumbers);
      if (list.empty()) s.fail("exposure_ms", "at least one exposure time", "an empty array");
      for (size_t i = 0; i < list.size(); ++i) {
        camera.exposure_ns.push_back(ms_to_ns(list[i]));
        check_within_interval(*n->as_array()->get(i), fmt::format("{}[{}]", s.key_path("exposure_ms"), i),
                              camera.exposure_ns.back());
      }
    } else {
      if (!n->is_number())
        s.fail("exposure_ms", "a number > 0 or an array of them (cycled per frame)", std::string(toml_type_phrase(*n)));
      camera.exposure_ns.push_back(milliseconds(s, "exposure_ms", 0, kPositive));
      check_within_interval(*n, s.key_path("exposure_ms"), camera.exposure_ns.back());
    }
  }
  if (camera.exposure_ns.front() > interval_ns)  // the default exposure at a high frame rate
    s.fail("fps",
           fmt::format("a frame interval of at least the exposure {:.6g} ms (camera.exposure_ms)",
                       camera.exposure_ns.front() / kNsPerMs),
           fmt::format("{} frames/s ({})", camera.fps, interval));

  camera.analogue_gain = s.number("analogue_gain", camera.analogue_gain, kPositive);
  camera.digital_gain = s.number("digital_gain", camera.digital_gain, kPositive);
  camera.readout_ns = milliseconds(s, "readout_ms", camera.readout_ns, kNonNegative);
  if (camera.readout_ns > interval_ns)
    s.fail("readout_ms", fmt::format("no more than {}", interval),
           fmt::format("{:.6g} ms", camera.readout_ns / kNsPerMs));

  camera.timestamp_meaning = s.parsed<TimestampMeaning>(
      "timestamp", camera.timestamp_meaning,
      [](std::string_view text) -> std::optional<TimestampMeaning> {
        TimestampMeaning meaning{};
        if (!timestamp_meaning_from_name(text, meaning)) return std::nullopt;
        return meaning;
      },
      "one of \"start_of_exposure\", \"end_of_frame\", \"sensor\"");
  camera.timestamp_offset_ns = milliseconds(s, "timestamp_offset_ms", camera.timestamp_offset_ns);
  camera.first_exposure_start_ns =
      milliseconds(s, "first_exposure_start_ms", camera.first_exposure_start_ns, kNonNegative);

  if (const auto ae = s.section("auto_exposure")) {
    SimAutoExposure& out = camera.auto_exposure;
    out.enabled = ae->boolean("enabled", out.enabled);
    out.target = ae->number("target", out.target, NumberRange::open_closed(0, 1));
    out.min_exposure_ns = milliseconds(*ae, "min_exposure_ms", out.min_exposure_ns, kPositive);
    if (const toml::node* n = ae->node("min_exposure_ms"))
      check_within_interval(*n, ae->key_path("min_exposure_ms"), out.min_exposure_ns);
    out.max_gain = ae->number("max_gain", out.max_gain, NumberRange::at_least(1));
  }

  if (const auto sensor = s.section("sensor")) {
    SimSensor& out = camera.sensor;
    out.sensitivity = sensor->number("sensitivity", out.sensitivity, kPositive);
    out.full_well_electrons = sensor->number("full_well_electrons", out.full_well_electrons, kPositive);
    out.read_noise_electrons = sensor->number("read_noise_electrons", out.read_noise_electrons, kNonNegative);
    out.noise = sensor->boolean("noise", out.noise);
    out.response = sensor->parsed<CameraResponse>("response", out.response, response_curve,
                                               "\"srgb\", \"linear\" or \"gamma:<g>\" with g > 0");
    // The black level is a raw sensor's: in codes of the Bayer format's depth, below full scale.
    if (sensor->has("black_level")) {
      const int bits = bayer_bit_depth(camera.pixel_format);
      if (bits == 0)
        sensor->fail_with("black_level", fmt::format("applies to raw Bayer pixel formats only, and camera.pixel_format is {}",
                                                     pixel_format_name(camera.pixel_format)));
      out.black_level = sensor->integer_as<int>("black_level", out.black_level, IntRange{0, (1 << bits) - 2});
    }
  }

  // A camera that sends JPEG: any of the YUV, RGB and grey formats, not a raw mosaic.
  camera.jpeg_quality = s.integer_as<int>("jpeg_quality", camera.jpeg_quality, IntRange{0, 100});
  if (camera.jpeg_quality > 0 && is_bayer(camera.pixel_format))
    s.fail_with("jpeg_quality", fmt::format("expected a JPEG quality only for RGB24, YUYV, GREY and NV12 frames "
                                            "(0 = off), found {} with camera.pixel_format the raw Bayer format {}",
                                            camera.jpeg_quality, pixel_format_name(camera.pixel_format)));
  if (const auto optics = s.section("optics")) {
    SimOptics& out = camera.optics;
    out.defocus_px = optics->number("defocus_px", out.defocus_px, NumberRange::closed(0, kMaxDefocusPx).in("px"));
    out.vignetting = optics->number("vignetting", out.vignetting, kUnitInterval);
  }
  return camera;
}

// ---- [render] ----------------------------------------------------------------------------------

SimRender read_render(const TomlSection& s) {
  SimRender render;
  render.samples_per_pixel = s.integer_as<int>("samples_per_pixel", render.samples_per_pixel, IntRange{1, 65536});
  if (samples_per_axis(render.samples_per_pixel) == 0)
    s.fail("samples_per_pixel", "a perfect square (1, 4, 9, 16, ...: a sqrt x sqrt grid in the pixel)",
           fmt::format("{}", render.samples_per_pixel));
  render.frames = s.integer_as<int>("frames", render.frames, IntRange{1, std::numeric_limits<int>::max()});
  render.seed = static_cast<uint64_t>(s.integer("seed", static_cast<int64_t>(render.seed), IntRange{0}));
  render.write_linear = s.boolean("write_linear", render.write_linear);
  return render;
}

// ---- [trajectory] ------------------------------------------------------------------------------

// A camera south of the origin, 0.5 m away, looking at it 53 degrees down: the anchor tag upright.
const SimKeyframe kDefaultKeyframe{0.0, {0.0, -0.3, 0.4}, {0, 0, 0}, {0, 0, 1}, 0.0};

SimKeyframe read_keyframe(const TomlSection& s, const SimKeyframe* previous) {
  SimKeyframe k = kDefaultKeyframe;
  k.time_s = s.number("time_s", k.time_s);
  if (previous != nullptr && !(k.time_s > previous->time_s))
    s.fail("time_s",
           fmt::format("a time after the previous keyframe's {} s (times must strictly increase)", previous->time_s),
           fmt::format("{} s", k.time_s));
  k.position = s.vec3("position", k.position);
  k.look_at = s.vec3("look_at", k.look_at);
  k.up = s.vec3("up", k.up);
  k.roll_rad = degrees(s, "roll_deg", k.roll_rad);
  const Vec3 view = k.look_at - k.position;
  if (norm(view) == 0)
    s.fail("look_at", fmt::format("a point other than the camera position {}", show(k.position)), show(k.look_at));
  if (norm(k.up) == 0) s.fail("up", "a non-zero direction", show(k.up));
  if (norm(cross(normalized(k.up), normalized(view))) < kMinUpAngleSine)
    s.fail("up", fmt::format("a direction not parallel to the viewing direction {} (look_at - position)", show(view)),
           fmt::format("{}{}, parallel to it", show(k.up), s.has("up") ? "" : " (the default)"));
  return k;
}

SimRandomPath read_random_path(const TomlSection& s) {
  SimRandomPath path;
  path.target = s.vec3("target", path.target);
  path.min_distance_m = s.number("min_distance_m", path.min_distance_m, kPositive);
  path.max_distance_m = s.number("max_distance_m", path.max_distance_m, kPositive);
  if (path.max_distance_m < path.min_distance_m)
    s.fail(s.has("max_distance_m") ? "max_distance_m" : "min_distance_m", "min_distance_m <= max_distance_m",
           fmt::format("min {} m > max {} m", path.min_distance_m, path.max_distance_m));
  const NumberRange elevation = NumberRange::open_closed(0, 90).in("degrees");
  path.min_elevation_rad = degrees(s, "min_elevation_deg", path.min_elevation_rad, elevation);
  path.max_elevation_rad = degrees(s, "max_elevation_deg", path.max_elevation_rad, elevation);
  if (path.max_elevation_rad < path.min_elevation_rad)
    s.fail(s.has("max_elevation_deg") ? "max_elevation_deg" : "min_elevation_deg",
           "min_elevation_deg <= max_elevation_deg",
           fmt::format("min {:.6g} deg > max {:.6g} deg", path.min_elevation_rad / kRadiansPerDegree,
                       path.max_elevation_rad / kRadiansPerDegree));
  path.max_blur_px = s.number("max_blur_px", path.max_blur_px, NumberRange::closed(0, 200).in("px"));
  return path;
}

SimTrajectory read_trajectory(const std::optional<TomlSection>& s) {
  SimTrajectory trajectory;
  if (!s) {
    trajectory.keyframes.push_back(kDefaultKeyframe);
    return trajectory;
  }
  trajectory.kind = s->choice("kind", trajectory.kind, kSimTrajectoryKindNames);
  if (trajectory.kind == SimTrajectory::Kind::Random) {
    forbid(*s, "keyframe", "kind = \"random\" takes its path from [trajectory.random]");
    if (const auto random = s->section("random")) trajectory.random = read_random_path(*random);
    return trajectory;
  }
  forbid(*s, "random", "[trajectory.random] needs kind = \"random\"");
  for (const TomlSection& k : table_array(*s, "keyframe", kMaxKeyframes))
    trajectory.keyframes.push_back(
        read_keyframe(k, trajectory.keyframes.empty() ? nullptr : &trajectory.keyframes.back()));
  if (trajectory.keyframes.empty())
    s->fail("keyframe", "at least one [[trajectory.keyframe]] (one: a still camera)",
            s->has("keyframe") ? "none" : "nothing");
  return trajectory;
}

// ---- [[object]] --------------------------------------------------------------------------------

// Fills the texture and, for two-tone textures, the plane's size.
void read_texture(const TomlSection& object, const TomlSection& s, SimObject& out) {
  if (!s.has("kind")) s.fail("kind", "one of " + choice_list<SimTexture::Kind>(kSimTextureKindNames), "nothing");
  SimTexture& t = out.material.texture;
  t.kind = s.choice("kind", SimTexture::Kind::None, kSimTextureKindNames);
  const std::string_view kind = choice_name<SimTexture::Kind>(kSimTextureKindNames, t.kind);
  if (out.material.kind == SimMaterial::Kind::Mirror)
    s.fail_with("kind", fmt::format("expected no texture on a mirror (only Lambertian materials have one), found a {} "
                                    "texture on a mirror",
                                    kind));
  const auto only = [&](const std::vector<std::string_view>& keys, std::string_view which) {
    for (const auto k : keys) forbid(s, k, fmt::format("it applies to {} textures only", which));
  };
  if (t.kind == SimTexture::Kind::Image) {
    only({"family", "id", "size_m", "rows", "cols", "square_m", "margin_squares", "dark", "light"},
         "apriltag or chessboard");
    if (!object.has("albedo")) out.material.albedo = {1, 1, 1};  // the image's own colours unless scaled
    t.image_path = asset_file(s, "image", "an image file (PNG or JPEG)");
    // The header's size is checked before anything decodes the image (sim_textures.cpp again).
    ImageHeader header;
    try {
      header = read_image_header(t.image_path);
    } catch (const AssetError& e) {
      s.fail_with("image", fmt::format("expected an image file (PNG or JPEG), found one that is not: {}", e.what()));
    }
    if (header.width > kMaxTextureSide || header.height > kMaxTextureSide ||
        header.width * header.height > kMaxTexturePixels)
      s.fail_with("image", fmt::format("expected an image of at most {} pixels a side and {} pixels in all, "
                                       "found \"{}\": {} x {} {}",
                                       kMaxTextureSide, kMaxTexturePixels, t.image_path.string(), header.width,
                                       header.height, header.format));
    if (!cv::haveImageReader(t.image_path.string()))
      s.fail_with("image",
                  fmt::format("expected an image file OpenCV can decode (PNG or JPEG), found \"{}\", which is not one",
                              t.image_path.string()));
    return;
  }
  forbid(s, "image", "it applies to image textures only");
  const std::string why_size =
      t.kind == SimTexture::Kind::AprilTag
          ? "the apriltag texture sets the plane's size (from texture.size_m)"
          : "the chessboard texture sets the plane's size (from texture.rows, cols, square_m, margin_squares)";
  forbid(object, "width_m", why_size);
  forbid(object, "height_m", why_size);
  forbid(object, "albedo", "a two-tone texture's colours are texture.dark and texture.light");
  t.dark = s.vec3("dark", t.dark, kUnitInterval);
  t.light = s.vec3("light", t.light, kUnitInterval);
  if (t.kind == SimTexture::Kind::AprilTag) {
    only({"rows", "cols", "square_m", "margin_squares"}, "chessboard");
    // libapriltag's family names: a name the library takes, not a choice of ours.
    t.family = s.string("family", "tag36h11");
    const TagFamilyPtr family = create_tag_family(t.family);
    if (!family) s.fail("family", "one of " + joined_tag_family_names(), toml_quoted(t.family));
    t.tag_id = s.integer_as<int>("id", 0, IntRange{0, static_cast<int64_t>(family->ncodes) - 1});
    const double size_m = s.number("size_m", 0.1, kPositive);
    // size_m is the black border's edge (AprilTag's tag size); the plane carries the whole pattern.
    out.width_m = out.height_m = size_m * family->total_width / family->width_at_border;
  } else {
    only({"family", "id", "size_m"}, "apriltag");
    t.rows = s.integer_as<int>("rows", 7, IntRange{2, 1000});
    t.cols = s.integer_as<int>("cols", 10, IntRange{2, 1000});
    const double square_m = s.number("square_m", 0.02, kPositive);
    t.margin_squares = s.number("margin_squares", 1.0, kNonNegative);
    out.width_m = (t.cols + 2 * t.margin_squares) * square_m;
    out.height_m = (t.rows + 2 * t.margin_squares) * square_m;
  }
}

// A sized builtin's size_m = [x, y, z]: metres, finite, each in (0, kMaxMeshSizeM]; the plane
// ignores z, which may then be 0.
constexpr double kMaxMeshSizeM = 1000.0;

Vec3 read_mesh_size(const TomlSection& s, std::string_view source) {
  if (source != "builtin:plane") return s.vec3("size_m", {0, 0, 0}, NumberRange::open_closed(0, kMaxMeshSizeM).in("m"));
  const Vec3 size = s.vec3("size_m", {0, 0, 0}, NumberRange::closed(0, kMaxMeshSizeM).in("m"));
  if (size[0] == 0 || size[1] == 0)
    s.fail("size_m", fmt::format("[x, y, z] with x and y in (0, {:g}] m (a plane ignores z)", kMaxMeshSizeM),
           fmt::format("{} (a zero side)", show(size)));
  return size;
}

// ---- [[object.keyframe]] -------------------------------------------------------------------------

// Between two keys the rotation takes the short way, which near a half turn is ill-defined (and
// lost to the float quaternions of an exported glTF): a bigger turn needs a key in between.
constexpr double kMaxKeyTurnDeg = 179.0;
// How closely an animated object's own position and rotation_deg must match its first key's.
constexpr double kPoseMatchM = 1e-9;
constexpr double kPoseMatchRad = 1e-9;

// One key of object `name`'s pose track; its position and rotation_deg default to the object's.
SimPoseKey read_pose_key(const TomlSection& k, const std::string& name, const Vec3& position, const Vec3& rotation_deg,
                         const SimPoseKey* previous) {
  if (!k.has("time_s"))
    k.fail("time_s", fmt::format("the key's time in seconds (>= 0) on object \"{}\"'s pose track", name), "nothing");
  SimPoseKey key;
  key.time_s = k.number("time_s", 0, kNonNegative.in("s"));
  if (previous != nullptr && !(key.time_s > previous->time_s))
    k.fail("time_s",
           fmt::format("a time after the previous key's {} s (object \"{}\": times must strictly increase)",
                       previous->time_s, name),
           fmt::format("{} s", key.time_s));
  key.T_world_object = SE3::from_rt(kRadiansPerDegree * k.vec3("rotation_deg", rotation_deg), k.vec3("position", position));
  if (previous != nullptr) {
    const double turn_deg = rotation_angle_between(previous->T_world_object, key.T_world_object) / kRadiansPerDegree;
    if (turn_deg > kMaxKeyTurnDeg)
      k.fail(k.has("rotation_deg") ? "rotation_deg" : "time_s",
             fmt::format("a turn of at most {:g} degrees from the previous key (object \"{}\": between two keys the "
                         "rotation takes the short way, ambiguous near a half turn; add a key in between)",
                         kMaxKeyTurnDeg, name),
             fmt::format("{:.6g} degrees", turn_deg));
  }
  return key;
}

// The object's pose track, if it has one; T_world_object becomes the first key's pose, which the
// object's own position and rotation_deg, when given, must match (else they would be ignored).
void read_pose_track(const TomlSection& s, SimObject& out, const Vec3& position, const Vec3& rotation_deg) {
  for (const TomlSection& k : table_array(s, "keyframe", kMaxObjectKeyframes))
    out.keyframes.push_back(
        read_pose_key(k, out.name, position, rotation_deg, out.keyframes.empty() ? nullptr : &out.keyframes.back()));
  if (out.keyframes.empty()) return;
  const SE3& first = out.keyframes.front().T_world_object;
  const std::string why = fmt::format("(object \"{}\" stands at its first key's pose before that key; leave it out "
                                      "or make them equal)",
                                      out.name);
  if (s.has("position") && norm(first.translation() - position) > kPoseMatchM)
    s.fail("position", fmt::format("the first keyframe's position {} {}", show(first.translation()), why), show(position));
  if (s.has("rotation_deg") && rotation_angle_between(first, out.T_world_object) > kPoseMatchRad)
    s.fail("rotation_deg",
           fmt::format("the first keyframe's rotation ({:.6g} degrees from this one) {}",
                       rotation_angle_between(first, out.T_world_object) / kRadiansPerDegree, why),
           show(rotation_deg));
  out.T_world_object = first;
}

SimObject read_object(const TomlSection& s, size_t index) {
  SimObject out;
  out.name = s.string("name", fmt::format("object{}", index));
  if (out.name.empty()) s.fail("name", "a non-empty name", "an empty string");
  out.shape = s.choice("shape", out.shape, kSimShapeNames);
  const std::string_view shape = choice_name<SimObject::Shape>(kSimShapeNames, out.shape);
  const auto only = [&](const std::vector<std::string_view>& keys, std::string_view which) {
    for (const auto k : keys) forbid(s, k, fmt::format("it applies to shape = \"{}\" only, this is a {}", which, shape));
  };
  const Vec3 position = s.vec3("position", {0, 0, 0});
  const Vec3 rotation_deg = s.vec3("rotation_deg", {0, 0, 0});
  out.T_world_object = SE3::from_rt(kRadiansPerDegree * rotation_deg, position);
  read_pose_track(s, out, position, rotation_deg);
  out.is_virtual = s.boolean("virtual", out.is_virtual);
  out.casts_shadows = s.boolean("casts_shadows", out.casts_shadows);

  out.material.kind = s.choice("material", out.material.kind, kSimMaterialKindNames);
  out.material.albedo = s.vec3("albedo", out.material.albedo, kUnitInterval);
  if (out.material.kind == SimMaterial::Kind::Mirror) {
    forbid(s, "specular", "a mirror reflects perfectly; specular is a Lambertian surface's glossy highlight");
    forbid(s, "shininess", "a mirror reflects perfectly; shininess is a Lambertian surface's glossy highlight");
  }
  out.material.specular = s.number("specular", out.material.specular, kUnitInterval);
  if (!s.has("specular")) forbid(s, "shininess", "it shapes the highlight that specular turns on; give specular too");
  out.material.shininess = s.number("shininess", out.material.shininess, NumberRange::closed(1, 100000));

  if (out.shape == SimObject::Shape::Plane) {
    only({"radius_m"}, "sphere");
    only({"mesh", "mesh_scale", "size_m"}, "mesh");
    const auto texture = s.section("texture");
    if (texture) read_texture(s, *texture, out);
    if (out.material.texture.kind == SimTexture::Kind::None || out.material.texture.kind == SimTexture::Kind::Image) {
      out.width_m = s.number("width_m", 1.0, kPositive);
      out.height_m = s.number("height_m", 1.0, kPositive);
    }
  } else if (out.shape == SimObject::Shape::Sphere) {
    only({"width_m", "height_m", "texture"}, "plane");
    only({"mesh", "mesh_scale", "size_m"}, "mesh");
    out.radius_m = s.number("radius_m", 0.05, kPositive);
  } else {
    only({"width_m", "height_m", "texture"}, "plane");
    only({"radius_m"}, "sphere");
    const std::string source = s.string("mesh", "");
    if (is_builtin_mesh_source(source)) {
      if (!make_builtin_mesh(source))
        s.fail("mesh", fmt::format("one of {} or a glTF 2.0 file", kBuiltinMeshNames), toml_quoted(source));
      out.mesh_builtin = source;
      if (s.has("size_m")) {
        if (!builtin_mesh_is_sized(source))
          s.fail_with("size_m", fmt::format("not allowed here: {} has a fixed size (scale it with mesh_scale); size_m "
                                            "applies to \"builtin:box\", \"builtin:cylinder\" and \"builtin:plane\"",
                                            toml_quoted(source)));
        out.mesh_size_m = read_mesh_size(s, source);
      }
    } else {
      forbid(s, "size_m",
             "a glTF mesh has its own size (scale it with mesh_scale); size_m applies to \"builtin:box\", "
             "\"builtin:cylinder\" and \"builtin:plane\"");
      out.mesh_path = asset_file(s, "mesh", fmt::format("a glTF 2.0 file (.gltf or .glb) or one of {}", kBuiltinMeshNames));
      try {
        load_gltf_mesh(out.mesh_path);  // the simulator loads it again; this makes a bad file a scene error
      } catch (const AssetError& e) {
        s.fail_with("mesh", fmt::format("expected a valid glTF 2.0 file, found one that is not ({}): {}",
                                        out.mesh_path.string(), e.what()));
      }
    }
    out.mesh_scale = s.number("mesh_scale", out.mesh_scale, kPositive);
  }
  return out;
}

// ---- [[light]], [sun], [environment] -----------------------------------------------------------

const NumberRange kAngularDiameter = NumberRange::closed_open(0, 180).in("degrees");

SimLight read_light(const TomlSection& s, size_t index) {
  SimLight out;
  out.name = s.string("name", fmt::format("light{}", index));
  if (out.name.empty()) s.fail("name", "a non-empty name", "an empty string");
  out.kind = s.choice("kind", out.kind, kSimLightKindNames);
  const std::string_view kind = choice_name<SimLight::Kind>(kSimLightKindNames, out.kind);
  const auto only = [&](const std::vector<std::string_view>& keys, std::string_view which) {
    for (const auto k : keys) forbid(s, k, fmt::format("it applies to kind = {} only, this is a {} light", which, kind));
  };
  out.color = s.vec3("color", out.color, kNonNegative);
  if (out.kind == SimLight::Kind::Directional) {
    only({"position", "intensity"}, "\"point\" or \"sphere\"");
    only({"radius_m"}, "\"sphere\"");
    out.direction_to_light = unit_direction(s, "direction", {0, 0, 1});
    out.irradiance = s.number("irradiance", 5.0, kNonNegative);
    out.angular_diameter_rad = degrees(s, "angular_diameter_deg", 0.0, kAngularDiameter);
    return out;
  }
  only({"direction", "irradiance", "angular_diameter_deg"}, "\"directional\"");
  if (out.kind == SimLight::Kind::Point) only({"radius_m"}, "\"sphere\"");
  out.position = s.vec3("position", {0, 0, 1});
  out.intensity = s.number("intensity", 1.0, kNonNegative);
  if (out.kind == SimLight::Kind::Sphere) out.radius_m = s.number("radius_m", 0.02, kPositive);
  return out;
}

// ENU: east = north x up, up = world +z; azimuth from north towards east.
Vec3 sun_direction(const Vec3& north, double azimuth_rad, double elevation_rad) {
  const Vec3 up{0, 0, 1};
  const Vec3 east = cross(north, up);
  const double c = std::cos(elevation_rad);
  return (std::sin(azimuth_rad) * c) * east + (std::cos(azimuth_rad) * c) * north + std::sin(elevation_rad) * up;
}

SimLight read_sun(const TomlSection& s, const Vec3& north, SimSun& sun) {
  sun.azimuth_rad = degrees(s, "azimuth_deg", 180 * kRadiansPerDegree);
  sun.elevation_rad = degrees(s, "elevation_deg", 45 * kRadiansPerDegree, NumberRange::closed(-90, 90).in("degrees"));
  SimLight light;
  light.name = "sun";
  light.kind = SimLight::Kind::Directional;
  light.is_sun = true;
  light.direction_to_light = sun_direction(north, sun.azimuth_rad, sun.elevation_rad);
  light.irradiance = s.number("irradiance", 1000.0, kNonNegative);
  light.color = s.vec3("color", light.color, kNonNegative);
  light.angular_diameter_rad = degrees(s, "angular_diameter_deg", 0.53 * kRadiansPerDegree, kAngularDiameter);
  return light;
}

SimEnvironment read_environment(const TomlSection& s) {
  SimEnvironment out;
  if (s.has("hdr")) {
    out.hdr_path = asset_file(s, "hdr", "a Radiance .hdr image");
    std::ifstream in(out.hdr_path, std::ios::binary);
    char magic[2] = {0, 0};
    in.read(magic, 2);
    if (magic[0] != '#' || magic[1] != '?')
      s.fail_with("hdr", fmt::format("expected a Radiance .hdr image (starting \"#?\"), found \"{}\", which is not one",
                                     out.hdr_path.string()));
    out.radiance = {1, 1, 1};  // with an image, radiance is its multiplier
  }
  out.radiance = s.vec3("radiance", out.radiance, kNonNegative);
  out.rotation_rad = degrees(s, "rotation_deg", out.rotation_rad);
  return out;
}

// Names must be unique: ground truth and messages refer to objects and lights by name.
template <typename Item>
void check_unique_names(const std::vector<TomlSection>& sections, const std::vector<Item>& items, std::string_view what) {
  std::set<std::string> seen;
  for (size_t i = 0; i < items.size(); ++i)
    if (!seen.insert(items[i].name).second)
      sections[i].fail("name", fmt::format("a name not used by another {}", what),
                       fmt::format("{} a second time", toml_quoted(items[i].name)));
}

SimScene read_scene(const TomlSection& top) {
  SimScene scene;
  scene.source_file = top.source_name();
  scene.description = top.string("description", "");
  if (const auto world = top.section("world")) scene.world_north = read_world(*world);
  if (const auto camera = top.section("camera")) scene.camera = read_camera(*camera);
  if (const auto render = top.section("render")) scene.render = read_render(*render);
  scene.trajectory = read_trajectory(top.section("trajectory"));

  const std::vector<TomlSection> objects = table_array(top, "object", kMaxObjects);
  for (size_t i = 0; i < objects.size(); ++i) scene.objects.push_back(read_object(objects[i], i));
  check_unique_names(objects, scene.objects, "object");

  const std::vector<TomlSection> lights = table_array(top, "light", kMaxLights);
  for (size_t i = 0; i < lights.size(); ++i) scene.lights.push_back(read_light(lights[i], i));
  check_unique_names(lights, scene.lights, "light");
  if (const auto sun = top.section("sun")) {
    scene.sun.emplace();
    scene.lights.push_back(read_sun(*sun, scene.world_north, *scene.sun));
    for (size_t i = 0; i < lights.size(); ++i)
      if (scene.lights[i].name == "sun")
        lights[i].fail("name", "a name other than \"sun\" (the [sun] table adds a light named \"sun\")",
                       toml_quoted("sun"));
  }
  if (const auto environment = top.section("environment")) scene.environment = read_environment(*environment);
  top.reject_stray_keys();
  return scene;
}

}  // namespace

SimScene parse_sim_scene(const std::string& text, const std::string& source_name,
                         const std::filesystem::path& base_dir) {
  try {
    const toml::table root = parse_toml(text, source_name);
    return read_scene(TomlSection(root, source_name, base_dir));
  } catch (const TomlInputError& e) {
    throw SceneError(e.what());
  }
}

SimScene load_sim_scene(const std::filesystem::path& path) {
  std::string why;
  const auto text = read_text_file(path, why);
  if (!text) throw SceneError(fmt::format("{}: cannot read scene file: {}", path.string(), why));
  SimScene scene = parse_sim_scene(*text, path.string(), path.parent_path());
  scene.source_file = path;
  return scene;
}

}  // namespace arpipe::sim
