// Shared helpers of the render stage tests: camera poses, a varied camera background, ground truth
// by ray casting through the camera model, and an independent sRGB reference.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <numbers>
#include <optional>
#include <string_view>
#include <vector>

#include "core/frame.h"
#include "core/geometry/camera_model.h"
#include "core/geometry/se3.h"
#include "core/pipeline/frame_context.h"
#include "core/pipeline/stage.h"
#include "render/gl_stages.h"

namespace arpipe::render_test {

// T_cam_world of a camera at `eye` looking at `target`, image up towards world +z.
inline SE3 look_at(const Vec3& eye, const Vec3& target) {
  const Vec3 forward = normalized(target - eye);
  const Vec3 up{0, 0, 1};
  const Vec3 down = normalized((dot(up, forward)) * forward - up);  // -up, made orthogonal to forward
  const Vec3 right = cross(down, forward);
  const Mat3 R_cam_world{{{right[0], right[1], right[2]}, {down[0], down[1], down[2]}, {forward[0], forward[1], forward[2]}}};
  return SE3(R_cam_world, -1.0 * mat_mul(R_cam_world, eye));
}

// Every channel runs through all 256 values within any 86-pixel stretch, so a region of the
// frame a few dozen pixels across exercises every byte value.
inline Frame varied_background(int width, int height) {
  Frame frame = Frame::allocate(PixelFormat::RGB24, width, height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      uint8_t* p = frame.data.data() + size_t(y) * frame.bytes_per_line + size_t(x) * 3;
      p[0] = uint8_t((x + 3 * y) & 255);
      p[1] = uint8_t((5 * x + y + 17) & 255);
      p[2] = uint8_t((3 * x + 7 * y + 101) & 255);
    }
  return frame;
}

// Independent sRGB transfer functions (IEC 61966-2-1), in double.
inline double decode_srgb(double encoded) {
  return encoded <= 0.04045 ? encoded / 12.92 : std::pow((encoded + 0.055) / 1.055, 2.4);
}
inline double encode_srgb(double linear) {
  linear = std::clamp(linear, 0.0, 1.0);
  return linear <= 0.0031308 ? 12.92 * linear : 1.055 * std::pow(linear, 1 / 2.4) - 0.055;
}
inline int encode_srgb_8bit(double linear) { return int(std::lround(255 * encode_srgb(linear))); }

struct Box {
  Vec3 min;
  Vec3 max;
};

// Which face of the box (0..5: -x, +x, -y, +y, -z, +z) a camera ray (camera frame) enters first,
// by the slab method in the world frame; nullopt when it misses.
inline std::optional<int> ray_hits_box(const SE3& T_cam_world, const Box& box, const Vec3& ray_cam) {
  const SE3 T_world_cam = T_cam_world.inverse();
  const Vec3 origin = T_world_cam.translation();
  const Vec3 direction = T_world_cam.rotate(ray_cam);
  double t_near = -INFINITY, t_far = INFINITY;
  int entering_face = -1;
  for (int axis = 0; axis < 3; ++axis) {
    const size_t a = size_t(axis);
    if (!std::isfinite(direction[a])) return std::nullopt;
    if (direction[a] == 0) {
      if (origin[a] < box.min[a] || origin[a] > box.max[a]) return std::nullopt;
      continue;
    }
    double t0 = (box.min[a] - origin[a]) / direction[a], t1 = (box.max[a] - origin[a]) / direction[a];
    int face = 2 * axis;  // entering through the min side
    if (t0 > t1) {
      std::swap(t0, t1);
      face = 2 * axis + 1;
    }
    if (t0 > t_near) {
      t_near = t0;
      entering_face = face;
    }
    t_far = std::min(t_far, t1);
  }
  if (t_near > t_far || t_near <= 0) return std::nullopt;
  return entering_face;
}

// The same for the ray through a pixel, unprojected by the camera model (mrcal).
inline std::optional<int> ray_hits_box(const CameraModel& camera, const SE3& T_cam_world, const Box& box,
                                       const Vec2& pixel) {
  const std::optional<Vec3> ray_cam = camera.unproject(pixel);
  if (!ray_cam) return std::nullopt;
  return ray_hits_box(T_cam_world, box, *ray_cam);
}

enum class PixelClass { Inside, Outside, Edge };

// Inside: the whole disc of radius `band` around the pixel centre sees the same face (the corners
// of the enclosing square are tested, enough because faces and the silhouette are convex in a
// pinhole image and nearly so through a mild lens); Outside: the centre and 16 points on that
// circle miss the box; Edge otherwise.
inline PixelClass classify_pixel(const CameraModel& camera, const SE3& T_cam_world, const Box& box, int x, int y,
                                 double band, int* face = nullptr) {
  const std::optional<int> centre = ray_hits_box(camera, T_cam_world, box, {double(x), double(y)});
  if (centre) {
    for (int corner = 0; corner < 4; ++corner) {
      const Vec2 p{x + ((corner & 1) ? band : -band), y + ((corner & 2) ? band : -band)};
      if (ray_hits_box(camera, T_cam_world, box, p) != centre) return PixelClass::Edge;
    }
    if (face) *face = *centre;
    return PixelClass::Inside;
  }
  for (int k = 0; k < 16; ++k) {
    const double angle = 2 * std::numbers::pi * k / 16;
    if (ray_hits_box(camera, T_cam_world, box, {x + band * std::cos(angle), y + band * std::sin(angle)}))
      return PixelClass::Edge;
  }
  return PixelClass::Outside;
}

struct PixelTruth {
  PixelClass cls = PixelClass::Edge;
  int face = -1;  // for Inside pixels
};

// classify_pixel for every pixel of the image (band <= 1), row by row. Pixel centres are
// unprojected in one batch; a pixel whose 5x5 neighbourhood of centres all see the same face (or
// all miss) is at least 1 px from any boundary of a convex outline, so only the pixels near the
// outline need the full test (mrcal's iterative unprojection is the cost here).
inline std::vector<PixelTruth> classify_image(const CameraModel& camera, const SE3& T_cam_world, const Box& box,
                                              double band) {
  const int width = camera.width(), height = camera.height();
  std::vector<Vec2> centres;
  centres.reserve(size_t(width) * height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) centres.push_back({double(x), double(y)});
  std::vector<Vec3> rays;
  camera.unproject(centres, rays);
  std::vector<int> hit(rays.size());
  for (size_t i = 0; i < rays.size(); ++i) hit[i] = ray_hits_box(T_cam_world, box, rays[i]).value_or(-1);

  std::vector<PixelTruth> truth(rays.size());
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const int here = hit[size_t(y) * width + x];
      bool uniform = x >= 2 && y >= 2 && x < width - 2 && y < height - 2;
      for (int dy = -2; uniform && dy <= 2; ++dy)
        for (int dx = -2; uniform && dx <= 2; ++dx) uniform = hit[size_t(y + dy) * width + (x + dx)] == here;
      PixelTruth& out = truth[size_t(y) * width + x];
      if (uniform) {
        out.cls = here >= 0 ? PixelClass::Inside : PixelClass::Outside;
        out.face = here;
      } else {
        out.cls = classify_pixel(camera, T_cam_world, box, x, y, band, &out.face);
      }
    }
  return truth;
}

// The render and composite stages, configured once per config.
class StageHarness {
 public:
  StageHarness() : stages_(make_gl_stages()) {}
  void configure(const Config& config) {
    for (auto& stage : stages_) stage->configure(config);
  }
  void process(FrameContext& ctx) {
    for (auto& stage : stages_) stage->process(ctx);
  }

 private:
  std::vector<std::unique_ptr<Stage>> stages_;
};

inline FrameContext make_context(const Frame& camera_frame, std::shared_ptr<const CameraModel> camera,
                                 const SE3& T_cam_world, TrackState state = TrackState::Tracking) {
  FrameContext ctx;
  ctx.camera = camera_frame;
  ctx.camera_model = std::move(camera);
  ctx.pose.state = state;
  ctx.pose.T_cam_world = T_cam_world;
  return ctx;
}

inline const StageTiming* find_timing(const FrameContext& ctx, std::string_view stage) {
  for (const StageTiming& timing : ctx.timings)
    if (timing.stage == stage) return &timing;
  return nullptr;
}

}  // namespace arpipe::render_test
