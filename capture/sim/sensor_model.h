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
  explicit SensorModel(const SimSensor& sensor);  // validated by the loader

  // The noise-free linear value (full scale 1.0) after both gains, before clipping.
  double expected_value(double radiance, const SensorExposure& exposure) const;
  // As expected_value, with shot noise and read noise drawn from rng (the same as expected_value
  // when the sensor's noise is off).
  double noisy_value(double radiance, const SensorExposure& exposure, SampleRng& rng) const;
  // Clips to [0, 1] and applies the response curve.
  double encode(double linear_value) const;
  // The inverse of the response curve on [0, 1].
  double decode(double encoded_value) const;
  // Rounds an encoded value in [0, 1] to 8 bits.
  static uint8_t quantize(double encoded_value);

 private:
  SimSensor sensor_;
  double gamma_ = 0;  // 0: sRGB or linear, else the gamma of "gamma:<g>"
};

}  // namespace arpipe::sim
