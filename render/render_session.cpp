// What the render and composite stages share: the one EGL context (made by the first configure,
// on the processing thread) and the layer that objects are drawn into.
#include "render/render_session.h"

#include "core/log.h"
#include "render/gl/render_errors.h"

namespace arpipe {

RenderSession::~RenderSession() {
  // GL objects can only be deleted through a current context; EGL frees them with it otherwise.
  try_make_current();
  layer_.reset();
}

void RenderSession::ensure_context(EglPlatformRequest egl_platform) {
  if (context_) {
    if (egl_platform != platform_request_)
      log::warn("render: egl_platform changed from \"{}\" to \"{}\"; the change takes effect after a restart",
                egl_platform_request_name(platform_request_), egl_platform_request_name(egl_platform));
    return;
  }
  auto context = std::make_unique<EglContext>(egl_platform);
  log::info("render: {} EGL platform{}, GL_RENDERER {}, {}", egl_platform_name(context->platform()),
            context->device_description().empty() ? "" : " (" + context->device_description() + ")",
            context->gl_renderer(), context->gl_version());
  layer_ = std::make_unique<VirtualLayer>(*context);
  context_ = std::move(context);
  platform_request_ = egl_platform;
}

void RenderSession::make_current() const {
  if (!context_) throw RenderError("the render stages have no GL context (configure() did not succeed)");
  context_->make_current();
}

bool RenderSession::try_make_current() const noexcept {
  if (!context_) return false;
  try {
    context_->make_current();
    return true;
  } catch (...) {
    return false;
  }
}

}  // namespace arpipe
