// The composite stage: puts the virtual layer over the camera frame (undistorted first when
// render.lens = "undistort") into ctx.output (RGB24), in linear light with premultiplied alpha.
// The layer's drawn rectangle is read back once per drawn layer (a reused one is not read again)
// and blended on the CPU: on llvmpipe uploading the camera's rectangle, a GL draw and reading the
// result back cost more than the blend itself.
#include "render/composite_stage.h"

#include <fmt/format.h>

#include <chrono>
#include <cstring>

#include "core/image/camera_response.h"
#include "core/image/premultiplied_blend.h"
#include "core/image/pixel_convert.h"
#include "core/log.h"
#include "core/pipeline/monotonic_clock.h"
#include "render/gl/gl_error.h"
#include "render/gl/render_errors.h"
#include "core/image/pixel_rect.h"

namespace arpipe {
namespace {

// The camera frame as it was, seen through the camera's own lens: converted ahead when it was.
void pass_through(FrameContext& ctx) {
  if (ctx.camera_rgb24.width == ctx.camera.width && ctx.camera_rgb24.height == ctx.camera.height &&
      ctx.camera_rgb24.format == PixelFormat::RGB24 && !ctx.camera_rgb24.data.empty()) {
    ctx.output = std::move(ctx.camera_rgb24);
  } else {
    ctx.output = Frame::allocate(PixelFormat::RGB24, ctx.camera.width, ctx.camera.height);
    to_rgb24(ctx.camera, ctx.output.data);
  }
  ctx.camera_rgb24 = Frame();
  ctx.output.meta = ctx.camera.meta;
  ctx.output_camera_model = ctx.camera_model;
}

}  // namespace

CompositeStage::CompositeStage(std::shared_ptr<RenderSession> session) : session_(std::move(session)) {}

CompositeStage::~CompositeStage() {
  session_->try_make_current();
  read_framebuffer_.reset();
}

void CompositeStage::configure(const Config& config) {
  // The virtual layer is linear light: it goes out through the same response the camera's pixels
  // came in by, so virtual and real brighten and darken together.
  response_ = config.light.response;  // parsed when the config was loaded
  encoder_ = ResponseEncoder(response_);
  lens_ = config.render.lens;
  layer_generation_ = 0;  // read the next layer afresh
  last_error_.clear();
}

void CompositeStage::prepare(const std::shared_ptr<const CameraModel>& camera_model) noexcept {
  if (!camera_model || lens_ != LensMode::Undistort) return;
  try {
    undistortion(camera_model);
  } catch (...) {
    // The cache keeps the error; the frames report it.
  }
}

std::shared_ptr<const LensUndistortion> CompositeStage::undistortion(
    const std::shared_ptr<const CameraModel>& camera_model) {
  return undistortions_.get(camera_model, [](const CameraModel& model) { return LensUndistortion(model); });
}

void CompositeStage::camera_picture(FrameContext& ctx) {
  if (lens_ != LensMode::Undistort) {
    pass_through(ctx);
    return;
  }
  const std::shared_ptr<const LensUndistortion> to_pinhole = undistortion(ctx.camera_model);
  if (ctx.camera.width != ctx.camera_model->width() || ctx.camera.height != ctx.camera_model->height())
    throw RenderError(fmt::format("the camera frame is {}x{} but the camera model is for {}x{}", ctx.camera.width,
                                  ctx.camera.height, ctx.camera_model->width(), ctx.camera_model->height()));
  if (distorted_.width != ctx.camera.width || distorted_.height != ctx.camera.height)
    distorted_ = Frame::allocate(PixelFormat::RGB24, ctx.camera.width, ctx.camera.height);
  to_rgb24(ctx.camera, distorted_.data);
  ctx.output = Frame::allocate(PixelFormat::RGB24, ctx.camera.width, ctx.camera.height);
  ctx.output.meta = ctx.camera.meta;
  to_pinhole->apply(distorted_, ctx.output);
  ctx.output_camera_model = to_pinhole->pinhole_core();
}

void CompositeStage::process_ahead(FrameContext& ctx) noexcept {
  if (lens_ == LensMode::Undistort) return;
  const auto start = std::chrono::steady_clock::now();
  try {
    ctx.camera_rgb24 = Frame::allocate(PixelFormat::RGB24, ctx.camera.width, ctx.camera.height);
    to_rgb24(ctx.camera, ctx.camera_rgb24.data);
    ctx.camera_rgb24_ms = milliseconds_since(start);
  } catch (...) {
    ctx.camera_rgb24 = Frame();  // process() converts it and reports what went wrong
  }
}

void CompositeStage::process(FrameContext& ctx) noexcept {
  const auto start = std::chrono::steady_clock::now();
  // The conversion done ahead counts as this stage's time.
  const auto elapsed_ms = [&, ahead_ms = ctx.camera_rgb24_ms] { return ahead_ms + milliseconds_since(start); };
  try {
    if (!ctx.virtual_layer_drawn) {
      camera_picture(ctx);
      ctx.record_timing(std::string(name()), elapsed_ms(), "nothing virtual drawn: pass-through");
      return;
    }
    composite(ctx);
    ctx.record_timing(std::string(name()), elapsed_ms());
    last_error_.clear();
  } catch (const std::exception& e) {
    if (last_error_ != e.what()) log::error("composite: {}", e.what());
    last_error_ = e.what();
    try {
      pass_through(ctx);
    } catch (...) {
      ctx.output = Frame();
    }
    ctx.record_timing(std::string(name()), elapsed_ms(), fmt::format("error: {}", e.what()));
  } catch (...) {
    ctx.record_timing(std::string(name()), elapsed_ms(), "error: unknown exception");
  }
}

void CompositeStage::read_layer(const VirtualLayerTexture& layer, const PixelRect& rect) {
  session_->make_current();
  if (read_framebuffer_.get() == 0) read_framebuffer_ = GlFramebuffer::create();
  glBindFramebuffer(GL_FRAMEBUFFER, read_framebuffer_.get());
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, layer.texture, 0);
  check_framebuffer_complete("the virtual layer, to read it");
  const size_t values = size_t(rect.width) * size_t(rect.height) * 4;
  layer_pixels_.resize(values);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  if (session_->layer().color_format() == GL_RGBA16F) {
    glReadPixels(rect.x, rect.y, rect.width, rect.height, GL_RGBA, GL_FLOAT, layer_pixels_.data());
  } else {
    // GL_SRGB8_ALPHA8: the bytes are the premultiplied colour sRGB-encoded, alpha linear.
    layer_bytes_.resize(values);
    glReadPixels(rect.x, rect.y, rect.width, rect.height, GL_RGBA, GL_UNSIGNED_BYTE, layer_bytes_.data());
    static const CameraResponse srgb = CameraResponse::srgb();
    for (size_t i = 0; i < values; ++i)
      layer_pixels_[i] = i % 4 == 3 ? layer_bytes_[i] / 255.0f : srgb.decode8(layer_bytes_[i]);
  }
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  check_gl("reading the virtual layer back");
}

void CompositeStage::composite(FrameContext& ctx) {
  const int width = ctx.camera.width, height = ctx.camera.height;
  const VirtualLayerTexture& layer = ctx.virtual_layer;
  const PixelRect rect{layer.x, layer.y, layer.rect_width, layer.rect_height};
  if (layer.texture == 0) throw RenderError("the frame's virtual layer names no texture");
  if (layer.width != width || layer.height != height)
    throw RenderError(fmt::format("the virtual layer is {}x{} but the camera frame is {}x{}", layer.width,
                                  layer.height, width, height));
  if (rect.empty() || rect.x < 0 || rect.y < 0 || rect.right() > width || rect.bottom() > height)
    throw RenderError("the virtual layer's drawn rectangle lies outside the frame");

  // Everything outside the rectangle is the camera picture unchanged; the rectangle is blended.
  camera_picture(ctx);
  // A layer the render stage handed on again (render.reuse_layer) is the one read last time.
  if (layer.generation == 0 || layer.generation != layer_generation_ || !(rect == layer_rect_)) {
    layer_generation_ = 0;
    read_layer(layer, rect);
    layer_generation_ = layer.generation;
    layer_rect_ = rect;
  }
  blend_premultiplied_over(layer_pixels_.data(), rect, response_, encoder_, ctx.output.data.data(),
                           ctx.output.bytes_per_line);
}

}  // namespace arpipe
