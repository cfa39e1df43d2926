// Frame timing and exposure of the simulated camera: when each frame and each row exposes, the
// metadata a real driver would report for it, and the auto-exposure loop.
#pragma once

#include <cstdint>

#include "capture/sim/sim_scene.h"
#include "core/frame.h"

namespace arpipe::sim {

struct ExposureSetting {
  int64_t exposure_ns = 0;
  double analogue_gain = 1;
  double digital_gain = 1;
};

// The metadata of frame `sequence` (0-based) as the simulated driver reports it: exposure start
// = first_exposure_start + round(sequence * 1e9 / fps) ns (exact integer arithmetic for integral
// and NTSC n*1000/1001 rates, so starts never drift), raw timestamp per the camera's
// timestamp_meaning and offset (Sensor stamps behave as StartOfExposure), such that
// exposure_start_from_raw() gives the exposure start back exactly. readout_ns is the camera's,
// frame_duration_ns the nominal interval, exposure and gains the setting's.
FrameMetadata simulated_frame_metadata(const SimCamera& camera, uint64_t sequence, const ExposureSetting& setting);

// When row `row` (0 = top) of a frame starts exposing: rows start evenly spread over readout_ns,
// the first at exposure_start_ns and the last (height - 1) at exposure_start_ns + readout_ns.
double row_exposure_start_s(const FrameMetadata& meta, int row, int height);  // seconds since meta.exposure_start_ns

// The nominal frame interval, 1e9 / fps rounded to ns (frame starts themselves do not drift: see
// simulated_frame_metadata).
int64_t frame_interval_ns(const SimCamera& camera);

// Auto-exposure (SimAutoExposure) or the camera's fixed / cycled exposure schedule.
// Without auto-exposure frame k uses exposure_ns[k % size] and the camera's gains. With it, the
// loop starts at exposure_ns[0] and the camera's gains; each update() scales exposure x analogue
// gain by target / mean (clamped to [1/4, 4] per frame; a mean <= 0 counts as x4), preferring
// exposure (less noise): exposure within [min_exposure_ns, frame interval], analogue gain within
// [min(1, camera gain), max(max_gain, camera gain)], rising only once exposure is at its maximum
// and falling before exposure does. The digital gain stays the camera's.
class ExposureControl {
 public:
  // Throws std::invalid_argument on fps <= 0, no exposure or a non-positive one.
  explicit ExposureControl(const SimCamera& camera);
  // The setting for frame `sequence`; call in order, after update() for the previous frame
  // (with auto-exposure it is the loop's current setting, whatever `sequence`).
  ExposureSetting setting(uint64_t sequence) const;
  // Feeds back the mean linear value (after gains, before clipping) of the frame just rendered.
  void update(double mean_linear_value);

 private:
  SimCamera camera_;
  ExposureSetting current_;  // auto-exposure's setting for the next frame
  int64_t max_exposure_ns_ = 0;
  double min_gain_ = 1;
  double max_gain_ = 1;
};

}  // namespace arpipe::sim
