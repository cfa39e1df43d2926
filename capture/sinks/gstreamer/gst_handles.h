// Owning handles for GStreamer objects (unref on scope exit), and the one gst_init of the process.
#pragma once

#include <gst/gst.h>

#include <memory>
#include <string>

namespace arpipe {

struct GstObjectUnref {
  void operator()(gpointer object) const { gst_object_unref(object); }
};
using GstElementHandle = std::unique_ptr<GstElement, GstObjectUnref>;
using GstBusHandle = std::unique_ptr<GstBus, GstObjectUnref>;

struct GstMessageUnref {
  void operator()(GstMessage* message) const { gst_message_unref(message); }
};
using GstMessageHandle = std::unique_ptr<GstMessage, GstMessageUnref>;

// gst_init once per process (thread-safe); throws std::runtime_error when GStreamer cannot start.
void ensure_gstreamer_initialised();

// "element: message (debug)" of an ERROR or WARNING message.
std::string gst_message_text(GstMessage* message);

}  // namespace arpipe
