// The simple capture generator: a smooth orbit over a printed AprilTag on a table, rendered by
// casting each pixel's rays (4x4 per pixel, area sampling) through the camera model onto the z=0 plane.
#include "capture/sim/tag_capture_generator.h"

#include <apriltag/apriltag.h>
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <thread>

#include "capture/recording/recording_writer.h"
#include "core/image/pixel_convert.h"
#include "core/track/tag_family.h"

namespace arpipe {

namespace fs = std::filesystem;

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;
constexpr int64_t kFirstExposureStartNs = 1'000'000'000;  // a monotonic-looking start, well away from 0
constexpr int kSamplesPerAxis = 4;                        // 4x4 area samples per pixel

// Linear reflectances (the light is white and of unit intensity).
using Rgb = std::array<float, 3>;
constexpr Rgb kPaper{0.80f, 0.80f, 0.78f};
constexpr Rgb kInk{0.025f, 0.025f, 0.03f};
constexpr Rgb kTable{0.42f, 0.41f, 0.38f};
constexpr Rgb kWall{0.30f, 0.32f, 0.36f};  // rays that miss the table (above the horizon)

void check_options(const TagCaptureOptions& o) {
  auto bad = [](const std::string& what) { throw std::invalid_argument("tag capture: " + what); };
  if (auto problem = check_image_size(o.pixel_format, o.width, o.height)) bad(*problem);
  if (o.frames <= 0) bad(fmt::format("frames must be positive, got {}", o.frames));
  if (!(o.fps > 0 && o.fps <= 1000)) bad(fmt::format("fps must be in (0, 1000], got {}", o.fps));
  const double interval_ns = 1e9 / o.fps;
  if (o.exposure_ns <= 0 || double(o.exposure_ns) > interval_ns)
    bad(fmt::format("exposure_ns must be in (0, {:.0f}] (one frame interval), got {}", interval_ns, o.exposure_ns));
  if (!(o.tag_size_m > 0 && o.tag_size_m < 10)) bad(fmt::format("tag size must be in (0, 10) m, got {}", o.tag_size_m));
  if (!(o.noise_sigma >= 0 && o.noise_sigma <= 64))
    bad(fmt::format("noise sigma must be in [0, 64], got {}", o.noise_sigma));
  if (o.look_away_frames < 0) bad(fmt::format("look_away_frames must not be negative, got {}", o.look_away_frames));
}

int64_t frame_interval_ns(const TagCaptureOptions& o) { return std::llround(1e9 / o.fps); }

// T_cam_world from the camera centre, its viewing direction and the world direction that should
// point down in the image (camera frame: x right, y down, z forward).
SE3 look_along(const Vec3& centre, const Vec3& forward_world, const Vec3& down_hint, double roll_rad) {
  const Vec3 z = normalized(forward_world);
  Vec3 y = normalized(down_hint - dot(down_hint, z) * z);
  Vec3 x = cross(y, z);
  // Roll about the viewing direction.
  const double c = std::cos(roll_rad), s = std::sin(roll_rad);
  const Vec3 x_rolled = c * x + s * y;
  y = cross(z, x_rolled);
  x = x_rolled;
  const Mat3 R{{{x[0], x[1], x[2]}, {y[0], y[1], y[2]}, {z[0], z[1], z[2]}}};
  return SE3(R, -1.0 * mat_mul(R, centre));
}

// The camera path at t seconds after the first exposure: an orbit 0.385-0.565 m from a point near
// the tag centre, 5-35 degrees from the tag normal, slowly turning about it (about 30 degrees/s).
SE3 camera_pose(double t, bool looking_away) {
  const double distance = 0.475 + 0.09 * std::sin(2 * kPi * t / 5.3);
  const double tilt = 20 * kDeg + 15 * kDeg * std::sin(2 * kPi * t / 3.7 + 0.4);
  // Starts south of the tag (at -y) so that the tag's top is up in the image.
  const double azimuth = -90 * kDeg + 2 * kPi * t / 12.0 + 0.3 * std::sin(2 * kPi * t / 7.1);
  const double roll = 4 * kDeg * std::sin(2 * kPi * t / 6.1);
  const Vec3 target{0.008 * std::sin(2 * kPi * t / 4.3), 0.006 * std::cos(2 * kPi * t / 5.9), 0.0};
  const Vec3 outward{std::cos(azimuth), std::sin(azimuth), 0.0};  // from the tag towards the camera, level
  const Vec3 centre =
      target + distance * Vec3{std::sin(tilt) * outward[0], std::sin(tilt) * outward[1], std::cos(tilt)};
  if (looking_away) {
    // Facing away from the tag and 31 degrees down at the table: the tag is behind the camera.
    return look_along(centre, outward + Vec3{0, 0, -0.6}, Vec3{0, 0, -1}, roll);
  }
  // Image "down" points back towards the camera's own side, as when holding a phone over a table.
  return look_along(centre, target - centre, outward, roll);
}

std::vector<double> lens_intrinsics(const TagCaptureOptions& o) {
  const double f = 520.0 * o.width / 640.0;
  const double cx = (o.width - 1) / 2.0 + 3.5, cy = (o.height - 1) / 2.0 - 2.5;
  std::vector<double> intrinsics{f, f, cx, cy};
  const std::array<double, 4> opencv4{-0.05, 0.012, 0.0004, -0.0003};  // k1, k2, p1, p2
  if (o.lensmodel == "LENSMODEL_PINHOLE") return intrinsics;
  if (o.lensmodel != "LENSMODEL_OPENCV4" && o.lensmodel != "LENSMODEL_OPENCV5" && o.lensmodel != "LENSMODEL_OPENCV8")
    throw std::invalid_argument(fmt::format(
        "tag capture: lens model \"{}\" is not supported (LENSMODEL_PINHOLE, LENSMODEL_OPENCV4, 5 or 8)", o.lensmodel));
  intrinsics.insert(intrinsics.end(), opencv4.begin(), opencv4.end());
  if (o.lensmodel == "LENSMODEL_OPENCV5") intrinsics.push_back(0.0);
  if (o.lensmodel == "LENSMODEL_OPENCV8") intrinsics.insert(intrinsics.end(), {0.0, 0.0, 0.0, 0.0});
  return intrinsics;
}

template <typename Fn>
void parallel_rows(int rows, Fn fn) {
  const int threads = int(std::clamp(std::thread::hardware_concurrency(), 1u, 8u));
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(fn, rows * t / threads, rows * (t + 1) / threads);
  fn(0, rows / threads);
  for (auto& thread : pool) thread.join();
}

// The printed tag (with its white border) as reflectances, row 0 at the top (+y world).
struct TagTexture {
  int cells = 0;
  double cell_m = 0;
  double half_extent_m = 0;  // half the printed square's side
  std::vector<Rgb> texels;

  explicit TagTexture(const TagCaptureOptions& o) {
    const TagFamilyPtr family = create_tag_family(o.family);
    if (!family)
      throw std::invalid_argument(fmt::format("tag capture: unknown tag family \"{}\" (known: {})", o.family,
                                              joined_tag_family_names()));
    if (o.tag_id < 0 || uint32_t(o.tag_id) >= family->ncodes)
      throw std::invalid_argument(
          fmt::format("tag capture: tag id {} is outside {}'s 0..{}", o.tag_id, o.family, family->ncodes - 1));
    image_u8_t* image = apriltag_to_image(family.get(), o.tag_id);
    cells = image->width;
    // AprilTag's tag size is the black-border edge: width_at_border cells of the printed total_width.
    cell_m = o.tag_size_m / family->width_at_border;
    half_extent_m = cells * cell_m / 2;
    texels.resize(size_t(cells) * cells);
    for (int row = 0; row < cells; ++row)
      for (int col = 0; col < cells; ++col) {
        const float white = image->buf[row * image->stride + col] / 255.0f;
        for (int c = 0; c < 3; ++c) texels[size_t(row) * cells + col][c] = kInk[c] + (kPaper[c] - kInk[c]) * white;
      }
    image_u8_destroy(image);
  }
};

// The world point a ray hits on the z=0 plane, or none (it goes up or along the plane).
struct PlaneHit {
  double x = 0, y = 0;
  bool hit = false;
};

class TagSceneRenderer {
 public:
  TagSceneRenderer(const CameraModel& model, const TagCaptureOptions& options)
      : width_(model.width()), height_(model.height()), texture_(options) {
    corner_rays_.resize(size_t(width_ + 1) * (height_ + 1));
    // Unprojection is iterative, so it is done once: the normalised ray (x/z, y/z) through every
    // pixel corner. Sub-pixel rays interpolate it bilinearly (smooth, errors far below 1e-3 px).
    parallel_rows(height_ + 1, [&](int begin, int end) {
      std::vector<Vec2> pixels;
      std::vector<Vec3> rays;
      for (int v = begin; v < end; ++v)
        for (int u = 0; u <= width_; ++u) pixels.push_back({u - 0.5, v - 0.5});
      model.unproject(pixels, rays);
      for (size_t i = 0; i < rays.size(); ++i) {
        const Vec3& r = rays[i];
        const bool ok = std::isfinite(r[0]) && r[2] > 0;
        corner_rays_[size_t(begin) * (width_ + 1) + i] = ok ? Vec2{r[0] / r[2], r[1] / r[2]} : Vec2{NAN, NAN};
      }
    });
    corner_hits_.resize(corner_rays_.size());
  }

  // Linear RGB per pixel (width*height*3) for the camera at T_cam_world.
  void render(const SE3& T_cam_world, std::vector<float>& linear) {
    const SE3 T_world_cam = T_cam_world.inverse();
    centre_ = T_world_cam.translation();
    rotation_ = T_world_cam.rotation();
    linear.resize(size_t(width_) * height_ * 3);
    parallel_rows(height_ + 1, [&](int begin, int end) {
      for (int v = begin; v < end; ++v)
        for (int u = 0; u <= width_; ++u) {
          const size_t i = size_t(v) * (width_ + 1) + u;
          corner_hits_[i] = intersect(corner_rays_[i]);
        }
    });
    parallel_rows(height_, [&](int begin, int end) {
      for (int v = begin; v < end; ++v)
        for (int u = 0; u < width_; ++u) shade_pixel(u, v, &linear[(size_t(v) * width_ + u) * 3]);
    });
  }

 private:
  PlaneHit intersect(const Vec2& n) const {
    if (!std::isfinite(n[0])) return {};
    const Vec3 direction = mat_mul(rotation_, Vec3{n[0], n[1], 1.0});
    if (direction[2] >= -1e-12) return {};
    const double s = -centre_[2] / direction[2];
    return {centre_[0] + s * direction[0], centre_[1] + s * direction[1], true};
  }

  // Bits of the half-planes outside the printed square that a point lies in.
  unsigned outside_bits(const PlaneHit& p) const {
    const double h = texture_.half_extent_m;
    return (p.x < -h ? 1u : 0u) | (p.x > h ? 2u : 0u) | (p.y < -h ? 4u : 0u) | (p.y > h ? 8u : 0u);
  }

  int texel_index(const PlaneHit& p) const {
    const int n = texture_.cells;
    const int col = std::clamp(int(std::floor((p.x + texture_.half_extent_m) / texture_.cell_m)), 0, n - 1);
    const int row = std::clamp(int(std::floor((texture_.half_extent_m - p.y) / texture_.cell_m)), 0, n - 1);
    return row * n + col;
  }

  const Rgb& reflectance(const PlaneHit& p) const {
    if (!p.hit) return kWall;
    if (outside_bits(p) != 0) return kTable;
    return texture_.texels[size_t(texel_index(p))];
  }

  void shade_pixel(int u, int v, float* out) const {
    const size_t stride = size_t(width_) + 1;
    const size_t i00 = size_t(v) * stride + u;
    const PlaneHit* h[4] = {&corner_hits_[i00], &corner_hits_[i00 + 1], &corner_hits_[i00 + stride],
                            &corner_hits_[i00 + stride + 1]};
    // The samples lie in the convex hull of the corners' hits (bilinear weights, then a
    // projective map), so when the corners agree on one convex region the pixel is uniform.
    if (h[0]->hit && h[1]->hit && h[2]->hit && h[3]->hit) {
      const unsigned common_outside =
          outside_bits(*h[0]) & outside_bits(*h[1]) & outside_bits(*h[2]) & outside_bits(*h[3]);
      const bool all_inside =
          (outside_bits(*h[0]) | outside_bits(*h[1]) | outside_bits(*h[2]) | outside_bits(*h[3])) == 0;
      const Rgb* uniform = nullptr;
      if (common_outside != 0) {
        uniform = &kTable;
      } else if (all_inside) {
        const int t = texel_index(*h[0]);
        if (texel_index(*h[1]) == t && texel_index(*h[2]) == t && texel_index(*h[3]) == t)
          uniform = &texture_.texels[size_t(t)];
      }
      if (uniform) {
        std::copy(uniform->begin(), uniform->end(), out);
        return;
      }
    }
    const Vec2& n00 = corner_rays_[i00];
    const Vec2& n10 = corner_rays_[i00 + 1];
    const Vec2& n01 = corner_rays_[i00 + stride];
    const Vec2& n11 = corner_rays_[i00 + stride + 1];
    Rgb sum{0, 0, 0};
    for (int j = 0; j < kSamplesPerAxis; ++j)
      for (int i = 0; i < kSamplesPerAxis; ++i) {
        const double a = (i + 0.5) / kSamplesPerAxis, b = (j + 0.5) / kSamplesPerAxis;
        const Vec2 n{(1 - a) * (1 - b) * n00[0] + a * (1 - b) * n10[0] + (1 - a) * b * n01[0] + a * b * n11[0],
                     (1 - a) * (1 - b) * n00[1] + a * (1 - b) * n10[1] + (1 - a) * b * n01[1] + a * b * n11[1]};
        const Rgb& r = reflectance(intersect(n));
        for (int c = 0; c < 3; ++c) sum[c] += r[c];
      }
    for (int c = 0; c < 3; ++c) out[c] = sum[c] / (kSamplesPerAxis * kSamplesPerAxis);
  }

  int width_, height_;
  TagTexture texture_;
  std::vector<Vec2> corner_rays_;
  std::vector<PlaneHit> corner_hits_;
  Vec3 centre_{};
  Mat3 rotation_{};
};

// 8-bit output: an sRGB response plus Gaussian sensor noise, deterministic for a seed.
class SensorResponse {
 public:
  SensorResponse(uint64_t seed, double noise_sigma) : seed_(seed) {
    for (size_t i = 0; i < srgb_.size(); ++i) {
      const double x = double(i) / (srgb_.size() - 1);
      const double encoded = x <= 0.0031308 ? 12.92 * x : 1.055 * std::pow(x, 1 / 2.4) - 0.055;
      srgb_[i] = float(255.0 * encoded);
    }
    // Normal deviates by Box-Muller, drawn once; pixels pick from them with a fast hash stream.
    uint64_t state = seed ^ 0x6a09e667f3bcc909ull;
    for (size_t i = 0; i < gaussian_.size(); i += 2) {
      const double u1 = (double(splitmix64(state) >> 11) + 0.5) * 0x1.0p-53;
      const double u2 = double(splitmix64(state) >> 11) * 0x1.0p-53;
      const double radius = std::sqrt(-2.0 * std::log(u1));
      gaussian_[i] = float(noise_sigma * radius * std::cos(2 * kPi * u2));
      gaussian_[i + 1] = float(noise_sigma * radius * std::sin(2 * kPi * u2));
    }
  }

  void apply(const std::vector<float>& linear, int width, int height, int frame_index,
             std::vector<uint8_t>& rgb) const {
    rgb.resize(linear.size());
    parallel_rows(height, [&](int begin, int end) {
      for (int v = begin; v < end; ++v) {
        uint64_t state = seed_ * 0x9e3779b97f4a7c15ull + uint64_t(frame_index) * 0xbf58476d1ce4e5b9ull + uint64_t(v);
        uint64_t bits = 0;
        int bits_left = 0;
        for (size_t i = size_t(v) * width * 3; i < size_t(v + 1) * width * 3; ++i) {
          if (bits_left == 0) {
            bits = splitmix64(state);
            bits_left = 4;
          }
          const float noise = gaussian_[bits & 0xffff];
          bits >>= 16;
          --bits_left;
          const float x = std::clamp(linear[i], 0.0f, 1.0f);
          const float value = srgb_[size_t(x * (srgb_.size() - 1) + 0.5f)] + noise;
          rgb[i] = uint8_t(std::clamp(std::lround(value), 0l, 255l));
        }
      }
    });
  }

 private:
  static uint64_t splitmix64(uint64_t& state) {
    uint64_t z = (state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }

  uint64_t seed_;
  std::vector<float> srgb_ = std::vector<float>(4097);         // linear [0, 1] -> 8-bit sRGB
  std::vector<float> gaussian_ = std::vector<float>(1 << 16);  // indexed by 16 random bits
};

FrameMetadata frame_metadata(const TagCaptureOptions& o, int index) {
  FrameMetadata m;
  m.sequence = uint64_t(index);
  m.exposure_start_ns = kFirstExposureStartNs + int64_t(index) * frame_interval_ns(o);
  m.exposure_ns = o.exposure_ns;
  m.readout_ns = 0;  // a global shutter
  m.frame_duration_ns = frame_interval_ns(o);
  m.analogue_gain = 1.0;
  m.digital_gain = 1.0;
  m.raw_timestamp_ns = m.exposure_start_ns;
  m.raw_timestamp_meaning = TimestampMeaning::StartOfExposure;
  m.timestamp_offset_ns = 0;
  return m;
}

}  // namespace

CameraModel tag_capture_camera_model(const TagCaptureOptions& options) {
  check_options(options);
  return CameraModel(options.lensmodel, lens_intrinsics(options), options.width, options.height);
}

std::vector<GroundTruthFrame> tag_capture_ground_truth(const TagCaptureOptions& options) {
  check_options(options);
  std::vector<GroundTruthFrame> truth;
  for (int i = 0; i < options.frames; ++i) {
    const FrameMetadata m = frame_metadata(options, i);
    const bool looking_away = i >= options.frames - options.look_away_frames;
    auto pose_at = [&](int64_t t_ns) { return camera_pose(double(t_ns - kFirstExposureStartNs) * 1e-9, looking_away); };
    GroundTruthFrame& frame_truth = truth.emplace_back();
    frame_truth.sequence = m.sequence;
    frame_truth.T_cam_world_start = pose_at(m.exposure_start_ns);
    frame_truth.T_cam_world_mid = pose_at(m.exposure_mid_ns());
    frame_truth.T_cam_world_end = pose_at(m.exposure_start_ns + m.exposure_ns + m.readout_ns);
  }
  return truth;
}

int generate_tag_capture(const fs::path& dir, const TagCaptureOptions& options) {
  const CameraModel model = tag_capture_camera_model(options);
  const std::vector<GroundTruthFrame> truth = tag_capture_ground_truth(options);
  TagSceneRenderer renderer(model, options);
  const SensorResponse sensor(options.seed, options.noise_sigma);

  RecordingInfo info;
  info.pixel_format = options.pixel_format;
  info.width = options.width;
  info.height = options.height;
  info.source = fmt::format("arpipe generate: {} id {} ({} m) on a table, {} frames at {} fps, {} {}, seed {}",
                            options.family, options.tag_id, options.tag_size_m, options.frames, options.fps,
                            options.lensmodel, pixel_format_name(options.pixel_format), options.seed);
  RecordingWriter writer(dir, info, model);

  std::vector<float> linear;
  std::vector<uint8_t> rgb;
  for (int i = 0; i < options.frames; ++i) {
    // No motion blur: the scene is rendered at the middle of the exposure.
    renderer.render(truth[size_t(i)].T_cam_world_mid, linear);
    sensor.apply(linear, options.width, options.height, i, rgb);
    Frame frame = from_rgb24(rgb.data(), options.width, options.height, options.pixel_format);
    frame.meta = frame_metadata(options, i);
    writer.append(frame, truth[size_t(i)]);
  }
  writer.flush();
  return options.frames;
}

}  // namespace arpipe
