// The sinks a config may ask for, each by its config key ("sinks.png"): made from the config at the
// start, made anew by a reload that changes its part of the config (the running one is flushed and
// closed first), and left running, untouched, by a reload that does not.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "core/config/config.h"
#include "core/pipeline/frame_sink.h"

namespace arpipe {

struct SinkSlot {
  std::string key;
  // Whether two configs ask for the same sink: its part of them is equal.
  std::function<bool(const Config&, const Config&)> same;
  // The sink this config asks for (its output opened, not yet replacing an earlier run's), or null
  // when the config asks for none. Throws, naming the file and the key, when the output cannot be
  // opened.
  std::function<std::unique_ptr<FrameSink>(const Config&)> make;
};

// What a reload does to the sinks, handed to the sink thread between two frames: for each key, the
// running sink (if any) is flushed and closed, and the new one (if any) started in its place.
struct SinkSwap {
  std::vector<std::pair<std::string, std::unique_ptr<FrameSink>>> sinks;
};

}  // namespace arpipe
