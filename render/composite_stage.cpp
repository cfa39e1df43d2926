// The composite stage: puts the virtual layer over the camera frame (undistorted first when
// render.lens = "undistort") into ctx.output (RGB24), in linear light with premultiplied alpha,
// doing GL work only inside the layer's drawn rectangle.
#include "render/composite_stage.h"

#include <fmt/format.h>

#include <chrono>
#include <cstring>

#include "core/image/camera_response.h"
#include "core/image/pixel_convert.h"
#include "core/log.h"
#include "core/pipeline/monotonic_clock.h"
#include "render/gl/fullscreen_triangle.h"
#include "render/gl/gl_error.h"
#include "render/gl/render_errors.h"
#include "core/image/pixel_rect.h"

namespace arpipe {
namespace {

// Pixel for pixel: GL rows are image rows in both textures and in the output.
constexpr std::string_view kCompositeFragmentShader = R"glsl(#version 300 es
precision highp float;
uniform highp sampler2D u_virtual_layer;  // linear, premultiplied alpha
uniform highp sampler2D u_camera;         // the camera's bytes, through its response
uniform int u_response;                   // light.response: 0 sRGB, 1 linear, 2 gamma
uniform float u_gamma;                    // 2: encoded = linear^(1/g)
out vec4 out_color;

vec3 decode_response(vec3 c) {
  if (u_response == 1) return c;
  if (u_response == 2) return pow(c, vec3(u_gamma));
  return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), step(vec3(0.04045), c));
}

vec3 encode_response(vec3 l) {
  l = clamp(l, 0.0, 1.0);
  if (u_response == 1) return l;
  if (u_response == 2) return pow(l, vec3(1.0 / u_gamma));
  return mix(l * 12.92, 1.055 * pow(l, vec3(1.0 / 2.4)) - 0.055, step(vec3(0.0031308), l));
}

void main() {
  ivec2 pixel = ivec2(gl_FragCoord.xy);
  vec4 virtual_layer = texelFetch(u_virtual_layer, pixel, 0);
  vec3 camera = decode_response(texelFetch(u_camera, pixel, 0).rgb);
  out_color = vec4(encode_response(virtual_layer.rgb + (1.0 - virtual_layer.a) * camera), 1.0);
}
)glsl";

// The camera frame as it was, seen through the camera's own lens.
void pass_through(FrameContext& ctx) {
  ctx.output = Frame::allocate(PixelFormat::RGB24, ctx.camera.width, ctx.camera.height);
  ctx.output.meta = ctx.camera.meta;
  to_rgb24(ctx.camera, ctx.output.data);
  ctx.output_camera_model = ctx.camera_model;
}

}  // namespace

CompositeStage::CompositeStage(std::shared_ptr<RenderSession> session) : session_(std::move(session)) {}

CompositeStage::~CompositeStage() {
  session_->try_make_current();
  program_ = GlProgram();
  empty_vertex_array_.reset();
  camera_texture_.reset();
  output_framebuffer_.reset();
  output_texture_.reset();
}

void CompositeStage::configure(const Config& config) {
  const LensMode lens = config.render.lens;
  session_->make_current();
  if (program_.id() == 0) {
    program_ = GlProgram("compositing", kFullScreenTriangleVertexShader, kCompositeFragmentShader);
    empty_vertex_array_ = GlVertexArray::create();
    glUseProgram(program_.id());
    glUniform1i(program_.uniform("u_virtual_layer"), 0);
    glUniform1i(program_.uniform("u_camera"), 1);
  }
  // The virtual layer is linear light: it goes out through the same response the camera's pixels
  // came in by, so virtual and real brighten and darken together.
  const CameraResponse& response = config.light.response;  // parsed when the config was loaded
  glUseProgram(program_.id());
  glUniform1i(program_.uniform("u_response"), response.kind() == CameraResponse::Kind::Linear  ? 1
                                               : response.kind() == CameraResponse::Kind::Gamma ? 2
                                                                                                 : 0);
  glUniform1f(program_.uniform("u_gamma"), static_cast<float>(response.gamma_value()));
  lens_ = lens;
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

void CompositeStage::process(FrameContext& ctx) noexcept {
  const auto start = std::chrono::steady_clock::now();
  try {
    if (!ctx.virtual_layer_drawn) {
      camera_picture(ctx);
      ctx.record_timing(std::string(name()), milliseconds_since(start), "nothing virtual drawn: pass-through");
      return;
    }
    composite(ctx);
    ctx.record_timing(std::string(name()), milliseconds_since(start));
    last_error_.clear();
  } catch (const std::exception& e) {
    if (last_error_ != e.what()) log::error("composite: {}", e.what());
    last_error_ = e.what();
    try {
      pass_through(ctx);
    } catch (...) {
      ctx.output = Frame();
    }
    ctx.record_timing(std::string(name()), milliseconds_since(start), fmt::format("error: {}", e.what()));
  } catch (...) {
    ctx.record_timing(std::string(name()), milliseconds_since(start), "error: unknown exception");
  }
}

void CompositeStage::ensure_targets(int width, int height) {
  if (width == width_ && height == height_) return;
  camera_texture_ = create_texel_texture(GL_RGB8, width, height);
  output_texture_ = create_texel_texture(GL_RGBA8, width, height);
  output_framebuffer_ = GlFramebuffer::create();
  glBindFramebuffer(GL_FRAMEBUFFER, output_framebuffer_.get());
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, output_texture_.get(), 0);
  check_framebuffer_complete("composite output");
  check_gl("allocating the composite targets");
  width_ = width;
  height_ = height;
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

  // Everything outside the rectangle is the camera picture unchanged; the rectangle is overwritten.
  camera_picture(ctx);
  session_->make_current();
  ensure_targets(width, height);

  glActiveTexture(GL_TEXTURE1);
  glBindTexture(GL_TEXTURE_2D, camera_texture_.get());
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glPixelStorei(GL_UNPACK_ROW_LENGTH, width);
  glPixelStorei(GL_UNPACK_SKIP_PIXELS, rect.x);
  glPixelStorei(GL_UNPACK_SKIP_ROWS, rect.y);
  glTexSubImage2D(GL_TEXTURE_2D, 0, rect.x, rect.y, rect.width, rect.height, GL_RGB, GL_UNSIGNED_BYTE,
                  ctx.output.data.data());
  glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
  glPixelStorei(GL_UNPACK_SKIP_PIXELS, 0);
  glPixelStorei(GL_UNPACK_SKIP_ROWS, 0);
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, layer.texture);

  glBindFramebuffer(GL_FRAMEBUFFER, output_framebuffer_.get());
  glViewport(0, 0, width, height);
  glEnable(GL_SCISSOR_TEST);
  glScissor(rect.x, rect.y, rect.width, rect.height);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_BLEND);
  glUseProgram(program_.id());
  glBindVertexArray(empty_vertex_array_.get());
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glBindVertexArray(0);
  glDisable(GL_SCISSOR_TEST);

  readback_.resize(size_t(rect.width) * rect.height * 4);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(rect.x, rect.y, rect.width, rect.height, GL_RGBA, GL_UNSIGNED_BYTE, readback_.data());
  check_gl("compositing");
  for (int row = 0; row < rect.height; ++row) {
    const uint8_t* from = readback_.data() + size_t(row) * rect.width * 4;
    uint8_t* to = ctx.output.data.data() + size_t(rect.y + row) * ctx.output.bytes_per_line + size_t(rect.x) * 3;
    for (int column = 0; column < rect.width; ++column) {
      to[3 * column] = from[4 * column];
      to[3 * column + 1] = from[4 * column + 1];
      to[3 * column + 2] = from[4 * column + 2];
    }
  }
}

}  // namespace arpipe
