// The composite stage: puts the virtual layer over the camera frame (undistorted first when
// render.lens = "undistort") into ctx.output (RGB24), in linear light with premultiplied alpha,
// reading back only the layer's drawn rectangle, once per drawn layer, and blending on the CPU.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/image/camera_response.h"
#include "core/image/pixel_rect.h"
#include "core/image/response_encoder.h"
#include "core/pipeline/stage.h"
#include "render/gl/gl_objects.h"
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
  // Takes the camera's response (light.response) and the lens mode.
  void configure(const Config& config) override;
  // With render.lens = "undistort", builds the camera model's undistortion before streaming starts.
  void prepare(const std::shared_ptr<const CameraModel>& camera_model) noexcept override;
  // ctx.output = the camera picture as RGB24 where nothing virtual is, and
  // encode_srgb(V.rgb + (1 - V.a) * decode_srgb(camera)) inside the drawn rectangle. The camera
  // picture is the camera's sRGB bytes as they were, or, with render.lens = "undistort", the frame
  // undistorted to its pinhole core (on the CPU, every frame); ctx.output_camera_model says which.
  // The layer is the texture the render stage named in ctx.virtual_layer, read back unless it is
  // the generation read last. Without a virtual layer this frame, no GL at all. On an error: the
  // camera frame as it was.
  void process(FrameContext& ctx) noexcept override;
  // Converts the camera frame to RGB24 (ctx.camera_rgb24), which the frame's process() then takes
  // instead of converting it there; not with render.lens = "undistort".
  void process_ahead(FrameContext& ctx) noexcept override;

 private:
  void camera_picture(FrameContext& ctx);
  std::shared_ptr<const LensUndistortion> undistortion(const std::shared_ptr<const CameraModel>& camera_model);
  void composite(FrameContext& ctx);
  // The layer's rect as RGBA floats into layer_pixels_.
  void read_layer(const VirtualLayerTexture& layer, const PixelRect& rect);

  std::shared_ptr<RenderSession> session_;  // first member: outlives the GL objects below
  GlFramebuffer read_framebuffer_;
  CameraResponse response_;
  ResponseEncoder encoder_;
  std::vector<float> layer_pixels_;  // the last layer read back: its rect, RGBA
  std::vector<uint8_t> layer_bytes_;
  uint64_t layer_generation_ = 0;    // VirtualLayerTexture::generation of layer_pixels_; 0: none
  PixelRect layer_rect_;
  std::string last_error_;
  LensMode lens_ = LensMode::Map;
  PerModelCache<LensUndistortion> undistortions_;
  Frame distorted_;  // the camera frame as RGB24 before undistortion, reused
};

}  // namespace arpipe
