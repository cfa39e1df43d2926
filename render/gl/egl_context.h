// A headless EGL display and GLES 3.0 context (no window surface: everything renders into FBOs).
// Platform choice follows RenderConfig::egl_platform: the EGL device platform or Mesa's surfaceless one.
#pragma once

#include <memory>
#include <string>
#include <string_view>

#include "core/config/egl_platform_request.h"

namespace arpipe {

enum class EglPlatform { Surfaceless, Device };
std::string_view egl_platform_name(EglPlatform platform);

class EglContext {
 public:
  // requested: Auto (a device when the EGL device platform lists one, else surfaceless),
  // Surfaceless or Device. Makes the new context current on the calling thread.
  // Throws RenderError saying what was tried and why each attempt failed.
  explicit EglContext(EglPlatformRequest requested);
  ~EglContext();
  EglContext(const EglContext&) = delete;
  EglContext& operator=(const EglContext&) = delete;

  // Whether this EGL offers the platform at all (client extension present, and a device for Device).
  static bool platform_available(EglPlatform platform);

  // Makes the context current on the calling thread unless it already is. Throws RenderError.
  void make_current() const;
  bool is_current() const;

  EglPlatform platform() const { return platform_; }
  const std::string& device_description() const { return device_description_; }  // empty for surfaceless
  const std::string& gl_renderer() const { return gl_renderer_; }
  const std::string& gl_version() const { return gl_version_; }
  bool has_gl_extension(std::string_view name) const;

 private:
  struct Handles;  // EGL handles, kept out of this header
  std::unique_ptr<Handles> egl_;
  EglPlatform platform_ = EglPlatform::Surfaceless;
  std::string device_description_;
  std::string gl_renderer_;
  std::string gl_version_;
  std::string gl_extensions_;
};

}  // namespace arpipe
