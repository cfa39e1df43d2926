// The simulated image sensor: photons to electrons (Poisson shot noise), read noise, gains,
// clipping, the response curve and 8-bit quantisation. All randomness comes from SampleRng.
#include "capture/sim/sensor_model.h"
#include "core/image/srgb.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace arpipe::sim {

namespace {

// Below this mean the Poisson distribution is drawn exactly (inversion); above it a normal with
// the same mean and variance is within ~1/(6 sqrt(50)) ~ 2% in skewness, invisible after
// quantisation, and costs O(1) instead of O(N) per draw.
constexpr double kExactPoissonBelow = 50.0;

// Two independent standard normals from two uniforms (Box-Muller). Written out here rather than
// std::normal_distribution, whose sequence differs between standard libraries.
struct NormalPair {
  double first;
  double second;
};
NormalPair standard_normal_pair(SampleRng& rng) {
  const double u1 = (double(rng.next_u32()) + 1.0) * (1.0 / 4294967296.0);  // (0, 1]: log is finite
  const double u2 = rng.uniform();
  const double radius = std::sqrt(-2.0 * std::log(u1));
  const double angle = 2.0 * std::numbers::pi * u2;
  return {radius * std::cos(angle), radius * std::sin(angle)};
}

// Exact Poisson(mean) by inversion of the CDF with one uniform; mean < kExactPoissonBelow, so
// exp(-mean) > 1e-22 stays a normal double and the loop runs about mean + 1 times.
double poisson_by_inversion(double mean, SampleRng& rng) {
  const double u = rng.uniform();
  double probability = std::exp(-mean);
  double cumulative = probability;
  int k = 0;
  // The cap only guards against rounding leaving cumulative a hair below u far in the tail.
  while (u >= cumulative && k < 1000) {
    ++k;
    probability *= mean / k;
    cumulative += probability;
  }
  return double(k);
}


double clip_unit(double v) {
  if (!(v > 0)) return 0;  // NaN counts as black, not as a poisoned pixel
  return std::min(v, 1.0);
}

}  // namespace

SensorModel::SensorModel(const SimSensor& sensor) : sensor_(sensor) {
  if (!(sensor.full_well_electrons > 0) || !std::isfinite(sensor.full_well_electrons))
    throw std::invalid_argument("sensor.full_well_electrons must be a positive number");
  if (!(sensor.read_noise_electrons >= 0) || !std::isfinite(sensor.read_noise_electrons))
    throw std::invalid_argument("sensor.read_noise_electrons must be zero or positive");
  response_ = sensor.response.kind();
  gamma_ = sensor.response.gamma_value();
}

double SensorModel::expected_value(double radiance, const SensorExposure& exposure) const {
  return radiance * exposure.exposure_s * sensor_.sensitivity * exposure.analogue_gain * exposure.digital_gain;
}

double SensorModel::noisy_value(double radiance, const SensorExposure& exposure, SampleRng& rng) const {
  if (!sensor_.noise) return expected_value(radiance, exposure);
  const double full_well = sensor_.full_well_electrons;
  const double mean_electrons = std::max(0.0, radiance * exposure.exposure_s * sensor_.sensitivity * full_well);
  const NormalPair normal = standard_normal_pair(rng);
  // Shot noise: exact Poisson (an integer count) for dim pixels; for bright ones a continuous
  // normal N(N, N), not rounded, so its mean and variance are exactly those of the Poisson.
  const double photo_electrons = mean_electrons < kExactPoissonBelow
                                     ? poisson_by_inversion(mean_electrons, rng)
                                     : mean_electrons + std::sqrt(mean_electrons) * normal.first;
  // Read noise is added before the analogue gain, like the sensor's own readout chain.
  const double electrons = photo_electrons + sensor_.read_noise_electrons * normal.second;
  return electrons / full_well * exposure.analogue_gain * exposure.digital_gain;
}

double SensorModel::encode(double linear_value) const {
  const double v = clip_unit(linear_value);
  switch (response_) {
    case CameraResponse::Kind::Srgb: return srgb_encode(v);
    case CameraResponse::Kind::Gamma: return std::pow(v, 1.0 / gamma_);
    case CameraResponse::Kind::Linear: break;
  }
  return v;
}

double SensorModel::decode(double encoded_value) const {
  const double e = clip_unit(encoded_value);
  switch (response_) {
    case CameraResponse::Kind::Srgb: return srgb_decode(e);
    case CameraResponse::Kind::Gamma: return std::pow(e, gamma_);
    case CameraResponse::Kind::Linear: break;
  }
  return e;
}

uint8_t SensorModel::quantize(double encoded_value) {
  const double v = clip_unit(encoded_value);
  return uint8_t(std::lround(v * 255.0));
}

}  // namespace arpipe::sim
