// Frame timing and exposure of the simulated camera: exact integer frame starts, the driver's raw
// timestamp, per-row exposure starts and the auto-exposure loop.
#include "capture/sim/exposure_control.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/pipeline/frame_times.h"

namespace arpipe::sim {

namespace {

void check_camera(const SimCamera& camera) {
  if (!(camera.fps > 0) || !std::isfinite(camera.fps))
    throw std::invalid_argument("camera.fps must be a positive number");
  if (camera.exposure_ns.empty()) throw std::invalid_argument("camera.exposure: at least one exposure time needed");
  for (size_t i = 0; i < camera.exposure_ns.size(); ++i)
    if (camera.exposure_ns[i] <= 0)
      throw std::invalid_argument("camera.exposure[" + std::to_string(i) + "] must be positive");
}

}  // namespace

int64_t frame_interval_ns(const SimCamera& camera) { return std::llround(1e9 / camera.fps); }

FrameMetadata simulated_frame_metadata(const SimCamera& camera, uint64_t sequence, const ExposureSetting& setting) {
  FrameMetadata meta;
  meta.sequence = sequence;
  meta.exposure_start_ns = camera.first_exposure_start_ns + frame_offset_ns(camera.fps, sequence);
  meta.exposure_ns = setting.exposure_ns;
  meta.readout_ns = camera.readout_ns;
  meta.frame_duration_ns = frame_interval_ns(camera);
  meta.analogue_gain = setting.analogue_gain;
  meta.digital_gain = setting.digital_gain;
  meta.raw_timestamp_meaning = camera.timestamp_meaning;
  meta.timestamp_offset_ns = camera.timestamp_offset_ns;
  // The inverse of exposure_start_from_raw(): the driver's clock is offset_ns behind ours, and an
  // end-of-frame stamp comes after the last row's exposure. Sensor stamps act as start of exposure.
  int64_t raw = meta.exposure_start_ns - camera.timestamp_offset_ns;
  if (camera.timestamp_meaning == TimestampMeaning::EndOfFrame) raw += setting.exposure_ns + camera.readout_ns;
  if (camera.timestamp_meaning == TimestampMeaning::EndOfExposure) raw += setting.exposure_ns;
  meta.raw_timestamp_ns = raw;
  return meta;
}

double row_exposure_start_s(const FrameMetadata& meta, int row, int height) {
  if (height <= 1) return 0;
  return double(row) / double(height - 1) * double(meta.readout_ns) * 1e-9;
}

ExposureControl::ExposureControl(const SimCamera& camera) : camera_(camera) {
  check_camera(camera);
  current_ = {camera.exposure_ns.front(), camera.analogue_gain, camera.digital_gain};
  if (!camera.auto_exposure.enabled) return;
  const SimAutoExposure& ae = camera.auto_exposure;
  if (ae.min_exposure_ns <= 0) throw std::invalid_argument("camera.auto_exposure.min_exposure must be positive");
  if (!(ae.target > 0)) throw std::invalid_argument("camera.auto_exposure.target must be positive");
  if (!(camera.analogue_gain > 0)) throw std::invalid_argument("camera.analogue_gain must be positive");
  max_exposure_ns_ = std::max(frame_interval_ns(camera), ae.min_exposure_ns);
  min_gain_ = std::min(1.0, camera.analogue_gain);
  max_gain_ = std::max(ae.max_gain, camera.analogue_gain);
  current_.exposure_ns = std::clamp(current_.exposure_ns, ae.min_exposure_ns, max_exposure_ns_);
}

ExposureSetting ExposureControl::setting(uint64_t sequence) const {
  if (camera_.auto_exposure.enabled) return current_;
  return {camera_.exposure_ns[sequence % camera_.exposure_ns.size()], camera_.analogue_gain, camera_.digital_gain};
}

void ExposureControl::update(double mean_linear_value) {
  if (!camera_.auto_exposure.enabled) return;
  const SimAutoExposure& ae = camera_.auto_exposure;
  // The image is linear in exposure x analogue gain, so one step of target / mean would land on
  // the target; the clamp keeps a single odd frame (a flash, a black frame) from swinging it far.
  const double factor =
      mean_linear_value > 0 ? std::clamp(ae.target / mean_linear_value, 0.25, 4.0) : 4.0;
  const double min_product = double(ae.min_exposure_ns) * min_gain_;
  const double max_product = double(max_exposure_ns_) * max_gain_;
  const double product =
      std::clamp(double(current_.exposure_ns) * current_.analogue_gain * factor, min_product, max_product);
  // Exposure first (gain adds noise): gain only covers what the longest exposure cannot, and it
  // is the first thing to go back down.
  const int64_t exposure =
      std::clamp(int64_t(std::llround(product / min_gain_)), ae.min_exposure_ns, max_exposure_ns_);
  current_.exposure_ns = exposure;
  current_.analogue_gain = exposure < max_exposure_ns_ ? min_gain_
                                                       : std::clamp(product / double(exposure), min_gain_, max_gain_);
}

}  // namespace arpipe::sim
