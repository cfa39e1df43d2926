// Replays a recording in place of a live camera: paced by the frames' timestamps or as fast as
// possible, optionally looping. Never drops frames (the pipeline blocks instead).
#pragma once

#include <cstdint>
#include <memory>

#include "core/config/config.h"
#include "core/pipeline/frame_source.h"

namespace arpipe {

class ReplaySource : public FrameSource {
 public:
  // Opens the recording named by config.path; throws RecordingError (bad recording), CameraModelError
  // (bad camera_model override, or one whose image size differs from the recording's) or ConfigError
  // (unknown pacing).
  explicit ReplaySource(const SourceConfig& config);
  ~ReplaySource() override;

  std::string describe() const override;
  bool is_live() const override { return false; }
  std::shared_ptr<const CameraModel> camera_model() const override;
  // Frames come with timestamp_offset_ns added to exposure_start_ns. Looping adds the recording's
  // duration plus one frame interval per pass to the timestamps (and its frame count to the
  // sequence numbers), so time and sequence never go backwards. A frame that fails its checksum
  // is logged, counted and skipped (Retry); an interrupt() during a pacing sleep returns Retry
  // and the frame comes with the next call. A looped recording whose frames fit
  // source.loop_cache_mb is read and checked on its first pass only: later passes copy the frames
  // kept from it (a change to the files during the replay is then not seen).
  // The recording's frame duration, else the mean spacing of its frames; nullopt for fewer than two
  // frames without a duration.
  std::optional<int64_t> frame_interval_ns() const override;
  SourceStatus next(Frame& frame) override;
  void interrupt() override;

  uint64_t frames_skipped() const;  // damaged frames left out so far

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace arpipe
