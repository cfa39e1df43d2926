// A headless EGL display and GLES 3.0 context (no window surface: everything renders into FBOs).
// Platform choice follows RenderConfig::egl_platform: the EGL device platform or Mesa's surfaceless one.
#include "render/gl/egl_context.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GLES3/gl3.h>

#include <fmt/format.h>

#include <map>
#include <mutex>
#include <optional>
#include <vector>

#include "core/log.h"
#include "render/gl/render_errors.h"

namespace arpipe {
namespace {

std::string egl_error_name(EGLint error) {
  switch (error) {
    case EGL_SUCCESS: return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED: return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS: return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC: return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE: return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG: return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT: return "EGL_BAD_CONTEXT";
    case EGL_BAD_CURRENT_SURFACE: return "EGL_BAD_CURRENT_SURFACE";
    case EGL_BAD_DISPLAY: return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH: return "EGL_BAD_MATCH";
    case EGL_BAD_NATIVE_PIXMAP: return "EGL_BAD_NATIVE_PIXMAP";
    case EGL_BAD_NATIVE_WINDOW: return "EGL_BAD_NATIVE_WINDOW";
    case EGL_BAD_PARAMETER: return "EGL_BAD_PARAMETER";
    case EGL_BAD_SURFACE: return "EGL_BAD_SURFACE";
    case EGL_CONTEXT_LOST: return "EGL_CONTEXT_LOST";
    default: return fmt::format("EGL error 0x{:04x}", error);
  }
}

std::string last_egl_error() { return egl_error_name(eglGetError()); }

bool has_word(std::string_view list, std::string_view word) {
  size_t pos = 0;
  while ((pos = list.find(word, pos)) != std::string_view::npos) {
    const bool starts = pos == 0 || list[pos - 1] == ' ';
    const size_t end = pos + word.size();
    if (starts && (end == list.size() || list[end] == ' ')) return true;
    pos = end;
  }
  return false;
}

std::string client_extensions() {
  // EGL_NO_DISPLAY query is itself an extension (EGL_EXT_client_extensions); NULL means none.
  const char* extensions = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  return extensions ? extensions : "";
}

// eglTerminate acts on the display, which EGL hands out once per platform and native display, so
// two contexts on one platform share it: terminate only when the last one goes.
std::mutex display_users_mutex;
std::map<EGLDisplay, int> display_users;

void acquire_display(EGLDisplay display) {
  std::lock_guard lock(display_users_mutex);
  ++display_users[display];
}

void release_display(EGLDisplay display) {
  std::lock_guard lock(display_users_mutex);
  if (--display_users[display] == 0) {
    display_users.erase(display);
    eglTerminate(display);
  }
}

struct EglDevice {
  EGLDeviceEXT handle = EGL_NO_DEVICE_EXT;
  bool software = false;
  std::string description;
};

std::vector<EglDevice> enumerate_devices() {
  const std::string extensions = client_extensions();
  if (!has_word(extensions, "EGL_EXT_platform_device") || !has_word(extensions, "EGL_EXT_device_enumeration"))
    return {};
  auto query_devices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
  auto query_device_string =
      reinterpret_cast<PFNEGLQUERYDEVICESTRINGEXTPROC>(eglGetProcAddress("eglQueryDeviceStringEXT"));
  if (!query_devices) return {};
  EGLint count = 0;
  if (!query_devices(0, nullptr, &count) || count <= 0) return {};
  std::vector<EGLDeviceEXT> handles(static_cast<size_t>(count));
  if (!query_devices(count, handles.data(), &count)) return {};
  handles.resize(static_cast<size_t>(count));

  std::vector<EglDevice> devices;
  for (size_t i = 0; i < handles.size(); ++i) {
    EglDevice device;
    device.handle = handles[i];
    std::string device_extensions;
    if (query_device_string) {
      const char* ext = query_device_string(handles[i], EGL_EXTENSIONS);
      device_extensions = ext ? ext : "";
    }
    device.software = has_word(device_extensions, "EGL_MESA_device_software");
    const char* node = nullptr;
    if (query_device_string && has_word(device_extensions, "EGL_EXT_device_drm_render_node"))
      node = query_device_string(handles[i], EGL_DRM_RENDER_NODE_FILE_EXT);
    if (!node && query_device_string && has_word(device_extensions, "EGL_EXT_device_drm"))
      node = query_device_string(handles[i], EGL_DRM_DEVICE_FILE_EXT);
    device.description = fmt::format("EGL device {}{}{}", i, device.software ? " (software)" : "",
                                     node ? fmt::format(" {}", node) : std::string());
    devices.push_back(std::move(device));
  }
  return devices;
}

// Through eglGetProcAddress rather than a direct call, so a libEGL that predates EGL 1.5 still
// links; both platforms require EGL_EXT_platform_base or EGL 1.5 anyway.
EGLDisplay get_platform_display(EGLenum platform, void* native_display) {
  if (auto get_ext = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT")))
    return get_ext(platform, native_display, nullptr);
  if (auto get_core = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYPROC>(eglGetProcAddress("eglGetPlatformDisplay")))
    return get_core(platform, native_display, nullptr);
  return EGL_NO_DISPLAY;
}

// Hardware first: the software device renders exactly as the surfaceless platform does.
std::optional<EglDevice> preferred_device() {
  std::vector<EglDevice> devices = enumerate_devices();
  for (const EglDevice& device : devices)
    if (!device.software) return device;
  if (!devices.empty()) return devices.front();
  return std::nullopt;
}

}  // namespace

struct EglContext::Handles {
  EGLDisplay display = EGL_NO_DISPLAY;
  EGLContext context = EGL_NO_CONTEXT;
};

std::string_view egl_platform_name(EglPlatform platform) {
  return platform == EglPlatform::Device ? "device" : "surfaceless";
}

bool EglContext::platform_available(EglPlatform platform) {
  if (platform == EglPlatform::Surfaceless) return has_word(client_extensions(), "EGL_MESA_platform_surfaceless");
  return !enumerate_devices().empty();
}

namespace {

// Initialises the display and creates a GLES 3.0 context on it; returns an explanation on failure.
std::optional<std::string> create_on_display(EGLDisplay display, EGLDisplay& out_display, EGLContext& out_context) {
  if (display == EGL_NO_DISPLAY) return fmt::format("eglGetPlatformDisplay failed ({})", last_egl_error());
  EGLint major = 0, minor = 0;
  if (!eglInitialize(display, &major, &minor)) return fmt::format("eglInitialize failed ({})", last_egl_error());
  acquire_display(display);
  auto fail = [&](std::string why) {
    release_display(display);
    return std::optional<std::string>(std::move(why));
  };
  const char* display_extensions_c = eglQueryString(display, EGL_EXTENSIONS);
  const std::string display_extensions = display_extensions_c ? display_extensions_c : "";
  if (!has_word(display_extensions, "EGL_KHR_surfaceless_context"))
    return fail("the display lacks EGL_KHR_surfaceless_context (needed to render into FBOs without a surface)");
  if (!eglBindAPI(EGL_OPENGL_ES_API)) return fail(fmt::format("eglBindAPI(GLES) failed ({})", last_egl_error()));

  EGLConfig config = EGL_NO_CONFIG_KHR;
  if (!has_word(display_extensions, "EGL_KHR_no_config_context")) {
    // SURFACE_TYPE 0 matches every config: no surface is ever made from it.
    const EGLint attributes[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_ES3_BIT, EGL_SURFACE_TYPE, 0, EGL_NONE};
    EGLint count = 0;
    if (!eglChooseConfig(display, attributes, &config, 1, &count) || count < 1)
      return fail(fmt::format("no EGL config supports OpenGL ES 3 ({})", last_egl_error()));
  }
  const EGLint context_attributes[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 0, EGL_NONE};
  EGLContext context = eglCreateContext(display, config, EGL_NO_CONTEXT, context_attributes);
  if (context == EGL_NO_CONTEXT)
    return fail(fmt::format("eglCreateContext(OpenGL ES 3.0) failed ({})", last_egl_error()));
  if (!eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context)) {
    std::string why = fmt::format("eglMakeCurrent without a surface failed ({})", last_egl_error());
    eglDestroyContext(display, context);
    return fail(std::move(why));
  }
  out_display = display;
  out_context = context;
  return std::nullopt;
}

}  // namespace

EglContext::EglContext(EglPlatformRequest requested) : egl_(std::make_unique<Handles>()) {
  const std::string extensions = client_extensions();
  std::vector<std::string> failures;

  if (requested != EglPlatformRequest::Surfaceless) {
    if (std::optional<EglDevice> device = preferred_device()) {
      EGLDisplay display = get_platform_display(EGL_PLATFORM_DEVICE_EXT, device->handle);
      if (auto why = create_on_display(display, egl_->display, egl_->context)) {
        failures.push_back(fmt::format("device platform ({}): {}", device->description, *why));
      } else {
        platform_ = EglPlatform::Device;
        device_description_ = device->description;
      }
    } else {
      failures.push_back(has_word(extensions, "EGL_EXT_platform_device")
                             ? "device platform: eglQueryDevicesEXT lists no device"
                             : "device platform: EGL lacks EGL_EXT_platform_device / EGL_EXT_device_enumeration");
    }
  }
  if (egl_->context == EGL_NO_CONTEXT && requested != EglPlatformRequest::Device) {
    if (has_word(extensions, "EGL_MESA_platform_surfaceless")) {
      EGLDisplay display = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY);
      if (auto why = create_on_display(display, egl_->display, egl_->context))
        failures.push_back(fmt::format("surfaceless platform: {}", *why));
      else
        platform_ = EglPlatform::Surfaceless;
    } else {
      failures.push_back("surfaceless platform: EGL lacks EGL_MESA_platform_surfaceless");
    }
  }
  if (egl_->context == EGL_NO_CONTEXT) {
    std::string message = fmt::format("cannot create a headless OpenGL ES 3.0 context (egl_platform = \"{}\"):",
                                      egl_platform_request_name(requested));
    for (const std::string& failure : failures) message += "\n  " + failure;
    throw RenderError(message);
  }
  for (const std::string& failure : failures) log::info("EGL: {} (using the {} platform)", failure, egl_platform_name(platform_));

  auto gl_string = [](GLenum name) {
    const GLubyte* value = glGetString(name);
    return value ? std::string(reinterpret_cast<const char*>(value)) : std::string();
  };
  gl_renderer_ = gl_string(GL_RENDERER);
  gl_version_ = gl_string(GL_VERSION);
  GLint extension_count = 0;
  glGetIntegerv(GL_NUM_EXTENSIONS, &extension_count);
  for (GLint i = 0; i < extension_count; ++i) {
    const GLubyte* name = glGetStringi(GL_EXTENSIONS, static_cast<GLuint>(i));
    if (name) gl_extensions_ += std::string(reinterpret_cast<const char*>(name)) + " ";
  }
}

EglContext::~EglContext() {
  if (egl_->context == EGL_NO_CONTEXT) return;
  if (eglGetCurrentContext() == egl_->context) eglMakeCurrent(egl_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  eglDestroyContext(egl_->display, egl_->context);
  release_display(egl_->display);
}

void EglContext::make_current() const {
  if (is_current()) return;
  if (!eglMakeCurrent(egl_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, egl_->context))
    throw RenderError(fmt::format("eglMakeCurrent failed ({})", last_egl_error()));
}

bool EglContext::is_current() const { return eglGetCurrentContext() == egl_->context; }

bool EglContext::has_gl_extension(std::string_view name) const { return has_word(gl_extensions_, name); }

}  // namespace arpipe
