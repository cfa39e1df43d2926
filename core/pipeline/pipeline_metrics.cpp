#include "core/pipeline/pipeline_metrics.h"

#include "core/pipeline/frame_context.h"

namespace arpipe {

void count_frame(PipelineMetrics& m, const FrameContext& ctx) {
  for (const StageTiming& t : ctx.timings) {
    StageStats& stats = m.stages[t.stage];
    ++stats.runs;
    stats.total_ms += t.ms;
    stats.seconds.add(t.ms * 1e-3);
    if (!t.skipped.empty()) ++stats.skips[t.skipped];
  }
  const bool tracked = ctx.pose.state == TrackState::Tracking;
  if (tracked) ++m.frames_tracked;
  if (tracked && ctx.pose.searched_window_only) ++m.frames_tracked_in_window;
  if (tracked && ctx.pose.image_still) ++m.frames_still;
  if (ctx.pose.state == TrackState::Predicted) ++m.frames_predicted;
  if (ctx.pose.state == TrackState::Lost) ++m.frames_lost;
}

}  // namespace arpipe
