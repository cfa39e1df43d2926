// The composite stage: puts the virtual layer over the camera frame into ctx.output (RGB24), in
// linear light with premultiplied alpha, doing GL work only inside the layer's drawn rectangle.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/pipeline/stage.h"
#include "render/gl_objects.h"
#include "render/gl_program.h"
#include "render/render_session.h"

namespace arpipe {

class CompositeStage final : public Stage {
 public:
  explicit CompositeStage(std::shared_ptr<RenderSession> session);
  ~CompositeStage() override;

  std::string_view name() const override { return "composite"; }
  // Compiles the shader once; the render stage (configured first) has made the context.
  void configure(const Config& config) override;
  // ctx.output = the camera frame as RGB24 (the camera's sRGB bytes as they were) where nothing
  // virtual is, and encode_srgb(V.rgb + (1 - V.a) * decode_srgb(camera)) inside the drawn
  // rectangle. Without a virtual layer this frame, no GL at all: a CPU conversion only.
  void process(FrameContext& ctx) noexcept override;

 private:
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
};

}  // namespace arpipe
