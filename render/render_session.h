// What the render and composite stages share: the one EGL context (made by the first configure,
// on the processing thread) and the layer that objects are drawn into. What was drawn on a frame
// travels in its FrameContext (FrameContext::virtual_layer).
#pragma once

#include <GLES3/gl3.h>

#include <memory>
#include <string>

#include "render/gl/egl_context.h"
#include "render/virtual_layer.h"

namespace arpipe {

class RenderSession {
 public:
  RenderSession() = default;
  ~RenderSession();
  RenderSession(const RenderSession&) = delete;
  RenderSession& operator=(const RenderSession&) = delete;

  // Creates the context and the virtual layer on the first call; throws RenderError when no
  // context can be made. The platform is fixed from then on: a later different request warns.
  void ensure_context(EglPlatformRequest egl_platform);
  bool has_context() const { return context_ != nullptr; }
  // Makes the context current on the calling thread; throws RenderError (also when there is none).
  void make_current() const;
  // As make_current, for destructors: reports nothing, returns whether the context is current.
  bool try_make_current() const noexcept;

  const EglContext& context() const { return *context_; }
  // Where the objects are drawn: at the camera image's size, or the pinhole canvas's with
  // render.lens = "map".
  VirtualLayer& layer() { return *layer_; }

 private:
  std::unique_ptr<EglContext> context_;
  EglPlatformRequest platform_request_ = EglPlatformRequest::Auto;
  std::unique_ptr<VirtualLayer> layer_;  // declared after the context: destroyed before it
};

}  // namespace arpipe
