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
// = first_exposure_start + sequence * frame interval (rounded to ns), raw timestamp per the
// camera's timestamp_meaning and offset, such that exposure_start_from_raw() gives the exposure
// start back exactly.
FrameMetadata simulated_frame_metadata(const SimCamera& camera, uint64_t sequence, const ExposureSetting& setting);

// When row `row` (0 = top) of a frame starts exposing: rows start evenly spread over readout_ns,
// the first at exposure_start_ns and the last (height - 1) at exposure_start_ns + readout_ns.
double row_exposure_start_s(const FrameMetadata& meta, int row, int height);  // seconds since meta.exposure_start_ns

// Auto-exposure (SimAutoExposure) or the camera's fixed / cycled exposure schedule.
class ExposureControl {
 public:
  explicit ExposureControl(const SimCamera& camera);
  // The setting for frame `sequence`; call in order, after update() for the previous frame.
  ExposureSetting setting(uint64_t sequence) const;
  // Feeds back the mean linear value (after gains, before clipping) of the frame just rendered.
  void update(double mean_linear_value);

 private:
  // (implementation's choice)
};

}  // namespace arpipe::sim
