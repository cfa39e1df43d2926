// Test helper for the track tests: a fresh TagTracker with a given config run over a recording's
// frames, looped past its end when asked for more (each pass a second later, so time goes on).
#pragma once

#include <memory>
#include <vector>

#include "capture/recording/recording_reader.h"
#include "core/track/tag_tracker.h"

namespace arpipe::test {

inline std::vector<FrameContext> tracked_capture(const RecordingReader& reader, const Config& config,
                                                 size_t frames = 0) {
  TagTracker tracker;
  tracker.configure(config);
  const auto camera = std::make_shared<CameraModel>(reader.camera_model());
  std::vector<FrameContext> out(frames ? frames : reader.frame_count());
  for (size_t i = 0; i < out.size(); ++i) {
    reader.read(i % reader.frame_count(), out[i].camera);
    out[i].camera.meta.exposure_start_ns += int64_t(i / reader.frame_count()) * 1'000'000'000;
    out[i].camera_model = camera;
    out[i].input_index = i;
    tracker.process(out[i]);
  }
  return out;
}

}  // namespace arpipe::test
