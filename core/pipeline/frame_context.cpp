#include "core/pipeline/frame_context.h"

namespace arpipe {

std::string_view track_state_name(TrackState state) {
  switch (state) {
    case TrackState::NotRun: return "not_run";
    case TrackState::Tracking: return "tracking";
    case TrackState::Predicted: return "predicted";
    case TrackState::Lost: return "lost";
  }
  return "?";
}

int64_t FrameContext::latency_origin_ns() const {
  constexpr int64_t kMaxPlausibleNs = 10'000'000'000;
  const FrameMetadata& m = camera.meta;
  int64_t end = 0;
  if (__builtin_add_overflow(m.exposure_start_ns, m.exposure_ns, &end) || __builtin_add_overflow(end, m.readout_ns, &end))
    return arrived_ns;
  return end > 0 && end <= arrived_ns && arrived_ns - end <= kMaxPlausibleNs ? end : arrived_ns;
}

}  // namespace arpipe
