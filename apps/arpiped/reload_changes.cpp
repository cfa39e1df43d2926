// What a reload changes, by config key (see reload_changes.h). Parts are compared with the
// structs' operator==, whatever their members' types.
#include "apps/arpiped/reload_changes.h"

namespace arpipe {
namespace {

// Appends `key` when the part of the two configs that `part` picks differs.
template <typename Part>
void note(std::vector<std::string>& keys, const char* key, const Config& a, const Config& b, Part part) {
  if (!(part(a) == part(b))) keys.push_back(key);
}

}  // namespace

std::vector<std::string> keys_needing_restart(const Config& running, const Config& next) {
  std::vector<std::string> keys;
  const SourceConfig &a = running.source, &b = next.source;
#define ARPIPE_SOURCE_KEY(member) \
  if (!(a.member == b.member)) keys.push_back("source." #member);
  ARPIPE_SOURCE_KEY(type)
  ARPIPE_SOURCE_KEY(path)
  ARPIPE_SOURCE_KEY(pacing)
  ARPIPE_SOURCE_KEY(loop)
  ARPIPE_SOURCE_KEY(timestamp_offset_ns)
  ARPIPE_SOURCE_KEY(camera_model)
  ARPIPE_SOURCE_KEY(device)
  ARPIPE_SOURCE_KEY(camera)
  ARPIPE_SOURCE_KEY(role)
  ARPIPE_SOURCE_KEY(width)
  ARPIPE_SOURCE_KEY(height)
  ARPIPE_SOURCE_KEY(fps)
  ARPIPE_SOURCE_KEY(pixel_format)
  ARPIPE_SOURCE_KEY(buffers)
  ARPIPE_SOURCE_KEY(exposure_us)
  ARPIPE_SOURCE_KEY(gain)
  ARPIPE_SOURCE_KEY(gain_unity)
  ARPIPE_SOURCE_KEY(timestamp_meaning)
  ARPIPE_SOURCE_KEY(readout_ns)
  ARPIPE_SOURCE_KEY(frame_timeout_ms)
  ARPIPE_SOURCE_KEY(reconnect_min_ms)
  ARPIPE_SOURCE_KEY(reconnect_max_ms)
#undef ARPIPE_SOURCE_KEY
  if (keys.empty() && !(a == b)) keys.push_back("source");  // a key not listed above
  note(keys, "pipeline.queue_depth", running, next, [](const Config& c) { return c.pipeline.queue_depth; });
  note(keys, "render.egl_platform", running, next, [](const Config& c) { return c.render.egl_platform; });
  note(keys, "control.socket", running, next, [](const Config& c) { return c.control.socket; });
  note(keys, "pipeline.sink_queue_depth", running, next, [](const Config& c) { return c.pipeline.sink_queue_depth; });
  return keys;
}

std::vector<std::string> changed_parts(const Config& running, const Config& next) {
  std::vector<std::string> parts;
  const Config &a = running, &b = next;
  note(parts, "track", a, b, [](const Config& c) { return c.track; });
  note(parts, "motion", a, b, [](const Config& c) { return c.motion; });

  note(parts, "light.source", a, b, [](const Config& c) { return c.light.source; });
  LightConfig light_rest = b.light;  // next's light section with the parts named above and below as running's
  light_rest.source = a.light.source;
  light_rest.probe = a.light.probe;
  light_rest.sun = a.light.sun;
  light_rest.environment = a.light.environment;
  if (!(light_rest == a.light)) parts.push_back("light");
  note(parts, "light.probe", a, b, [](const Config& c) { return c.light.probe; });
  note(parts, "light.sun", a, b, [](const Config& c) { return c.light.sun; });
  note(parts, "light.environment", a, b, [](const Config& c) { return c.light.environment; });

  RenderConfig render_rest = b.render;
  render_rest.objects = a.render.objects;
  render_rest.blur = a.render.blur;
  render_rest.shadows = a.render.shadows;
  render_rest.prt = a.render.prt;
  render_rest.egl_platform = a.render.egl_platform;  // needs a restart
  if (!(render_rest == a.render)) parts.push_back("render");
  note(parts, "render.objects", a, b, [](const Config& c) { return c.render.objects; });
  note(parts, "render.blur", a, b, [](const Config& c) { return c.render.blur; });
  note(parts, "render.shadows", a, b, [](const Config& c) { return c.render.shadows; });
  note(parts, "render.prt", a, b, [](const Config& c) { return c.render.prt; });

  note(parts, "sinks.png", a, b, [](const Config& c) { return c.sinks.png; });
  note(parts, "sinks.y4m", a, b, [](const Config& c) { return c.sinks.y4m; });
  note(parts, "sinks.recording", a, b, [](const Config& c) { return c.sinks.recording; });
  note(parts, "sinks.results", a, b, [](const Config& c) { return c.sinks.results; });
  note(parts, "sinks.http", a, b, [](const Config& c) { return c.sinks.http; });
  note(parts, "sinks.v4l2", a, b, [](const Config& c) { return c.sinks.v4l2; });
  note(parts, "sinks.gstreamer", a, b, [](const Config& c) { return c.sinks.gstreamer; });

  note(parts, "pipeline.max_frames", a, b, [](const Config& c) { return c.pipeline.max_frames; });
  note(parts, "pipeline.log_level", a, b, [](const Config& c) { return c.pipeline.log_level; });
  return parts;
}

}  // namespace arpipe
