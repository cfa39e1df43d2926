// The map that bends a pinhole picture into the real lens's picture (render.lens = "map"): for
// every pixel of the lens image, where its ray meets an enlarged pinhole canvas. Pure CPU, mrcal.
#include "render/lens/lens_warp_map.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <thread>

#include "render/gl/render_errors.h"

namespace arpipe {
namespace {

// mrcal's unprojection solves to ~1e-8 px; a ray that lands further than this from its pixel came
// from a region where the distortion is not one-to-one.
constexpr double kRoundTripTolerancePx = 1e-3;
// Canvas texels kept beyond the outermost sample of the warp (lens_warp_pass.cpp) to spare.
constexpr int kCanvasMarginPx = 1;
// GL_MAX_TEXTURE_SIZE is at least 2048 in GLES 3.0 and 16384 on llvmpipe; a 75-degree lens of
// ordinary focal length needs far less (3.7 f each side).
constexpr int kMaxCanvasSidePx = 16384;

std::string pixel_name(const Vec2& pixel) { return fmt::format("({:g}, {:g})", pixel[0], pixel[1]); }

// Unit rays of many pixels, on up to 4 threads (CameraModel's const methods may run concurrently).
std::vector<Vec3> unproject_all(const CameraModel& model, const std::vector<Vec2>& pixels) {
  std::vector<Vec3> rays(pixels.size());
  const size_t threads = pixels.size() < 4096 ? 1 : std::clamp<size_t>(std::thread::hardware_concurrency(), 1, 4);
  const size_t chunk = (pixels.size() + threads - 1) / threads;
  auto work = [&](size_t begin) {
    const size_t end = std::min(pixels.size(), begin + chunk);
    if (begin >= end) return;
    const std::vector<Vec2> part(pixels.begin() + std::ptrdiff_t(begin), pixels.begin() + std::ptrdiff_t(end));
    std::vector<Vec3> out;
    model.unproject(part, out);
    std::copy(out.begin(), out.end(), rays.begin() + std::ptrdiff_t(begin));
  };
  std::vector<std::thread> workers;
  for (size_t t = 1; t < threads; ++t) workers.emplace_back(work, t * chunk);
  work(0);
  for (std::thread& worker : workers) worker.join();
  return rays;
}

// Rays through `pixels`, each checked: unprojectable, projecting back onto its pixel, and within
// kMaxOffAxisDeg of the axis. Throws RenderError naming the model and the first bad pixel.
std::vector<Vec3> checked_rays(const CameraModel& model, const std::vector<Vec2>& pixels) {
  if (!model.has_core())
    throw RenderError(fmt::format("lens model {} has no pinhole core (fx, fy, cx, cy), so render.lens = \"map\" "
                                  "cannot draw it on a pinhole canvas",
                                  model.lensmodel()));
  std::vector<Vec3> rays = unproject_all(model, pixels);
  std::vector<Vec2> back;
  model.project(rays, back);
  size_t widest = 0;
  double widest_cos = 2;
  for (size_t i = 0; i < pixels.size(); ++i) {
    const Vec3& ray = rays[i];
    if (!std::isfinite(ray[0]) || !std::isfinite(ray[1]) || !std::isfinite(ray[2]))
      throw RenderError(fmt::format("lens model {}: mrcal cannot unproject pixel {} (the distortion is not "
                                    "invertible there), so render.lens = \"map\" cannot use it",
                                    model.lensmodel(), pixel_name(pixels[i])));
    if (ray[2] < widest_cos) widest_cos = ray[2], widest = i;  // rays are unit length
    const double miss = std::hypot(back[i][0] - pixels[i][0], back[i][1] - pixels[i][1]);
    if (ray[2] > 0 && !(miss <= kRoundTripTolerancePx))
      throw RenderError(fmt::format("lens model {}: the ray through pixel {} projects back {:.3g} px away: the "
                                    "distortion folds over there (it is not one-to-one), so render.lens = \"map\" "
                                    "cannot use it",
                                    model.lensmodel(), pixel_name(pixels[i]), miss));
  }
  const double widest_deg = std::acos(std::clamp(widest_cos, -1.0, 1.0)) * 180 / std::numbers::pi;
  if (widest_deg > kMaxOffAxisDeg)
    throw RenderError(fmt::format(
        "lens model {} sees rays {:.1f} degrees off its axis (pixel {}); a pinhole canvas holds at most {:g} degrees "
        "(a {:g}-degree field of view), so render.lens = \"map\" cannot draw it; render.lens = \"undistort\" keeps "
        "the part of the view its pinhole core sees",
        model.lensmodel(), widest_deg, pixel_name(pixels[widest]), kMaxOffAxisDeg, 2 * kMaxOffAxisDeg));
  return rays;
}

std::vector<Vec2> border_pixels(int width, int height) {
  std::vector<Vec2> pixels;
  for (int x = 0; x < width; ++x) pixels.push_back({double(x), 0.0}), pixels.push_back({double(x), height - 1.0});
  for (int y = 1; y + 1 < height; ++y) pixels.push_back({0.0, double(y)}), pixels.push_back({width - 1.0, double(y)});
  return pixels;
}

}  // namespace

LensWarpMap::LensWarpMap(const CameraModel& model, double canvas_scale)
    : lensmodel_(model.lensmodel()), width_(model.width()), height_(model.height()) {
  if (model.is_pinhole()) {
    identity_ = true;
    canvas_ = {model.fx(), model.fy(), model.cx(), model.cy(), width_, height_};
    return;
  }
  if (!(canvas_scale >= kMinCanvasScale && canvas_scale <= kMaxCanvasScale))
    throw RenderError(fmt::format("the lens canvas scale must lie in [{:g}, {:g}], not {:g}", kMinCanvasScale,
                                  kMaxCanvasScale, canvas_scale));
  // Scaled about pixel edges: canvas pixel k spans core pixels [k - 0.5, k + 0.5] / scale.
  const double fx = canvas_scale * model.fx(), fy = canvas_scale * model.fy();
  const double cx = canvas_scale * (model.cx() + 0.5) - 0.5, cy = canvas_scale * (model.cy() + 0.5) - 0.5;
  std::vector<Vec2> pixels;
  pixels.reserve(size_t(width_) * height_);
  for (int y = 0; y < height_; ++y)
    for (int x = 0; x < width_; ++x) pixels.push_back({double(x), double(y)});
  const std::vector<Vec3> rays = checked_rays(model, pixels);

  std::vector<Vec2> core(rays.size());
  double min_u = INFINITY, min_v = INFINITY, max_u = -INFINITY, max_v = -INFINITY;
  for (size_t i = 0; i < rays.size(); ++i) {
    core[i] = {fx * rays[i][0] / rays[i][2] + cx, fy * rays[i][1] / rays[i][2] + cy};
    min_u = std::min(min_u, core[i][0]), max_u = std::max(max_u, core[i][0]);
    min_v = std::min(min_v, core[i][1]), max_v = std::max(max_v, core[i][1]);
  }
  max_texels_per_pixel_ = 0;
  for (int y = 0; y < height_; ++y)
    for (int x = 0; x < width_; ++x) {
      const Vec2& c = core[size_t(y) * width_ + x];
      if (x + 1 < width_) {
        const Vec2& right = core[size_t(y) * width_ + x + 1];
        max_texels_per_pixel_ = std::max(max_texels_per_pixel_, std::hypot(right[0] - c[0], right[1] - c[1]));
      }
      if (y + 1 < height_) {
        const Vec2& below = core[size_t(y + 1) * width_ + x];
        max_texels_per_pixel_ = std::max(max_texels_per_pixel_, std::hypot(below[0] - c[0], below[1] - c[1]));
      }
    }
  // The canvas camera is the scaled core; its principal point moves so that the outermost
  // samples of the warp (and the texels they read) land kCanvasMarginPx inside.
  const double reach = tap_reach();
  const double left = std::floor(min_u - reach) - kCanvasMarginPx, top = std::floor(min_v - reach) - kCanvasMarginPx;
  const double canvas_width = std::floor(max_u + reach) + 2 + kCanvasMarginPx - left;
  const double canvas_height = std::floor(max_v + reach) + 2 + kCanvasMarginPx - top;
  if (canvas_width > kMaxCanvasSidePx || canvas_height > kMaxCanvasSidePx)
    throw RenderError(fmt::format("lens model {} would need a {:g}x{:g} pinhole canvas (at most {} a side), so "
                                  "render.lens = \"map\" cannot draw it",
                                  lensmodel_, canvas_width, canvas_height, kMaxCanvasSidePx));
  canvas_ = {fx, fy, cx - left, cy - top, int(canvas_width), int(canvas_height)};
  canvas_xy_.resize(2 * core.size());
  for (size_t i = 0; i < core.size(); ++i) {
    canvas_xy_[2 * i] = static_cast<float>(core[i][0] - left);
    canvas_xy_[2 * i + 1] = static_cast<float>(core[i][1] - top);
  }
}

Vec2 LensWarpMap::at(int x, int y) const {
  if (identity_) return {double(x), double(y)};
  const size_t i = 2 * (size_t(y) * width_ + x);
  return {canvas_xy_[i], canvas_xy_[i + 1]};
}

PixelRect LensWarpMap::canvas_rect_for(const PixelRect& image_rect) const {
  if (identity_ || image_rect.empty()) return image_rect;
  double min_u = INFINITY, min_v = INFINITY, max_u = -INFINITY, max_v = -INFINITY;
  auto add = [&](int x, int y) {
    const Vec2 c = at(x, y);
    min_u = std::min(min_u, c[0]), max_u = std::max(max_u, c[0]);
    min_v = std::min(min_v, c[1]), max_v = std::max(max_v, c[1]);
  };
  for (int x = image_rect.x; x < image_rect.right(); ++x) add(x, image_rect.y), add(x, image_rect.bottom() - 1);
  for (int y = image_rect.y; y < image_rect.bottom(); ++y) add(image_rect.x, y), add(image_rect.right() - 1, y);
  // A tap at c reads texels floor(c) and floor(c) + 1 (texel i is centred on coordinate i).
  const double reach = tap_reach();
  const int x0 = std::max(0, int(std::floor(min_u - reach)) - 1), y0 = std::max(0, int(std::floor(min_v - reach)) - 1);
  const int x1 = std::min(canvas_.width, int(std::floor(max_u + reach)) + 3);
  const int y1 = std::min(canvas_.height, int(std::floor(max_v + reach)) + 3);
  return {x0, y0, std::max(0, x1 - x0), std::max(0, y1 - y0)};
}

void check_lens_warpable(const CameraModel& model) {
  if (model.is_pinhole()) return;
  checked_rays(model, border_pixels(model.width(), model.height()));
}

}  // namespace arpipe
