#include "capture/sinks/gstreamer/gst_handles.h"

#include <fmt/format.h>

#include <mutex>
#include <stdexcept>

namespace arpipe {

void ensure_gstreamer_initialised() {
  static std::once_flag once;
  static std::string failure;
  std::call_once(once, [] {
    GError* error = nullptr;
    if (!gst_init_check(nullptr, nullptr, &error)) {
      failure = error ? error->message : "gst_init_check failed";
      if (error) g_error_free(error);
    }
  });
  if (!failure.empty()) throw std::runtime_error("GStreamer cannot start: " + failure);
}

std::string gst_message_text(GstMessage* message) {
  GError* error = nullptr;
  gchar* debug = nullptr;
  if (GST_MESSAGE_TYPE(message) == GST_MESSAGE_ERROR)
    gst_message_parse_error(message, &error, &debug);
  else if (GST_MESSAGE_TYPE(message) == GST_MESSAGE_WARNING)
    gst_message_parse_warning(message, &error, &debug);
  std::string text = fmt::format("{}: {}", GST_MESSAGE_SRC_NAME(message) ? GST_MESSAGE_SRC_NAME(message) : "?",
                                 error ? error->message : GST_MESSAGE_TYPE_NAME(message));
  if (debug && *debug) text += fmt::format(" ({})", debug);
  if (error) g_error_free(error);
  g_free(debug);
  return text;
}

}  // namespace arpipe
