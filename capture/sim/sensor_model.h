// The simulated image sensor: linear radiance through exposure, photon shot noise, read noise,
// gains, clipping, the response curve and 8-bit quantisation (SimSensor says the units).
#pragma once

#include <cstdint>

#include "capture/sim/sample_rng.h"
#include "capture/sim/sim_scene.h"

namespace arpipe::sim {

struct SensorExposure {
  double exposure_s = 0;
  double analogue_gain = 1;
  double digital_gain = 1;
};

class SensorModel {
 public:
  // Validated by the loader; still throws std::invalid_argument on a non-positive full well or a
  // negative read noise, naming the key.
  explicit SensorModel(const SimSensor& sensor);

  // The noise-free linear value (full scale 1.0) after both gains, before clipping.
  double expected_value(double radiance, const SensorExposure& exposure) const;
  // As expected_value, with shot noise and read noise drawn from rng (the same as expected_value
  // when the sensor's noise is off). Shot noise is exact Poisson below 50 electrons and an
  // unrounded normal of variance N above; read noise is normal; both before the analogue gain.
  double noisy_value(double radiance, const SensorExposure& exposure, SampleRng& rng) const;
  // Clips to [0, 1] (NaN to 0) and applies the response curve; full scale encodes to exactly 1.
  double encode(double linear_value) const;
  // The inverse of the response curve on [0, 1].
  double decode(double encoded_value) const;
  // Rounds an encoded value to 8 bits: round(v * 255) clamped to 0..255 (NaN to 0).
  static uint8_t quantize(double encoded_value);

 private:
  SimSensor sensor_;
  CameraResponse::Kind response_ = CameraResponse::Kind::Srgb;
  double gamma_ = 0;  // the g of "gamma:<g>"
};

}  // namespace arpipe::sim
