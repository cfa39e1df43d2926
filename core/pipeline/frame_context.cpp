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

}  // namespace arpipe
