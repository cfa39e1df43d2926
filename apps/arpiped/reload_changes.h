// What a reload changes, by config key: the keys the running pipeline cannot take (they need a
// restart), and the parts it applies, for the log line that answers the SIGHUP.
#pragma once

#include <string>
#include <vector>

#include "core/config/config.h"

namespace arpipe {

// The source (opened once), the queues (pipeline.queue_depth) and the GL context
// (render.egl_platform) are made once at the start: each of their keys that differs, by name.
std::vector<std::string> keys_needing_restart(const Config& running, const Config& next);

// What differs, part by part ("light.source", "sinks.png", "render.blur"; a section's name alone
// for its other keys), in the config's order.
std::vector<std::string> changed_parts(const Config& running, const Config& next);

}  // namespace arpipe
