// The composite stage: puts the virtual layer over the camera frame (undistorted first when
// render.lens = "undistort") into ctx.output (RGB24), in linear light with premultiplied alpha,
// doing GL work only inside the layer's drawn rectangle.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/pipeline/stage.h"
#include "render/gl/gl_objects.h"
#include "render/gl/gl_program.h"
#include "render/lens/lens_mode.h"
#include "render/lens/lens_undistortion.h"
#include "render/lens/per_model_cache.h"
#include "render/render_session.h"

namespace arpipe {

class CompositeStage final : public Stage {
 public:
  explicit CompositeStage(std::shared_ptr<RenderSession> session);
  ~CompositeStage() override;

  std::string_view name() const override { return "composite"; }
  // Compiles the shader once; the render stage (configured first) has made the context.
  void configure(const Config& config) override;
  // With render.lens = "undistort", builds the camera model's undistortion before streaming starts.
  void prepare(const std::shared_ptr<const CameraModel>& camera_model) noexcept override;
  // ctx.output = the camera picture as RGB24 where nothing virtual is, and
  // encode_srgb(V.rgb + (1 - V.a) * decode_srgb(camera)) inside the drawn rectangle. The camera
  // picture is the camera's sRGB bytes as they were, or, with render.lens = "undistort", the frame
  // undistorted to its pinhole core (on the CPU, every frame); ctx.output_camera_model says which.
  // The layer is the texture the render stage named in ctx.virtual_layer. Without a virtual layer
  // this frame, no GL at all. On an error: the camera frame as it was.
  void process(FrameContext& ctx) noexcept override;

 private:
  void camera_picture(FrameContext& ctx);
  std::shared_ptr<const LensUndistortion> undistortion(const std::shared_ptr<const CameraModel>& camera_model);
  void composite(FrameContext& ctx);
  void ensure_targets(int width, int height);

  std::shared_ptr<RenderSession> session_;  // first member: outlives the GL objects below
  GlProgram program_;
  GlVertexArray empty_vertex_array_;
  GlTexture camera_texture_;
  GlTexture output_texture_;
  GlFramebuffer output_framebuffer_;
  int width_ = 0;
  int height_ = 0;
  std::vector<uint8_t> readback_;
  std::string last_error_;
  LensMode lens_ = LensMode::Map;
  PerModelCache<LensUndistortion> undistortions_;
  Frame distorted_;  // the camera frame as RGB24 before undistortion, reused
};

}  // namespace arpipe
