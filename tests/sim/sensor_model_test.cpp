// SensorModel against physics and the published sRGB curve: linear response, Poisson shot noise
// plus Gaussian read noise with the right mean and variance, response curves and 8-bit edges.
#include "capture/sim/sensor_model.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace arpipe::sim {
namespace {

SimSensor linear_sensor(bool noise) {
  SimSensor sensor;
  sensor.sensitivity = 100.0;
  sensor.full_well_electrons = 10000.0;
  sensor.read_noise_electrons = 3.0;
  sensor.noise = noise;
  sensor.response = CameraResponse::linear();
  return sensor;
}

struct Moments {
  double mean = 0;
  double variance = 0;  // unbiased sample variance
};

Moments moments(const std::vector<double>& values) {
  double sum = 0;
  for (double v : values) sum += v;
  Moments m;
  m.mean = sum / double(values.size());
  double squares = 0;
  for (double v : values) squares += (v - m.mean) * (v - m.mean);
  m.variance = squares / double(values.size() - 1);
  return m;
}

TEST(SensorModel, ExpectedValueIsRadianceTimesExposureSensitivityAndGains) {
  const SensorModel sensor(linear_sensor(true));
  // 0.5 W/m^2/sr for 4 ms at 100 full-scale units per (W/m^2/sr s): 0.2 of full scale, x 1.5 x 2.
  EXPECT_NEAR(sensor.expected_value(0.5, {0.004, 1.5, 2.0}), 0.5 * 0.004 * 100 * 1.5 * 2.0, 1e-15);
  EXPECT_EQ(sensor.expected_value(0.0, {0.004, 1.5, 2.0}), 0.0);
}

TEST(SensorModel, ExpectedValueDoublesWithExposureAndEitherGain) {
  const SensorModel sensor(linear_sensor(false));
  const SensorExposure base{0.003, 1.25, 1.5};
  const double v = sensor.expected_value(0.37, base);
  // Doubling is exact in binary floating point, so the products double exactly too.
  EXPECT_EQ(sensor.expected_value(0.37, {0.006, 1.25, 1.5}), 2 * v);
  EXPECT_EQ(sensor.expected_value(0.37, {0.003, 2.5, 1.5}), 2 * v);
  EXPECT_EQ(sensor.expected_value(0.37, {0.003, 1.25, 3.0}), 2 * v);
  EXPECT_EQ(sensor.expected_value(0.74, base), 2 * v);
}

TEST(SensorModel, NoiseOffGivesTheExpectedValueExactly) {
  const SensorModel sensor(linear_sensor(false));
  SampleRng rng(7, 3);
  for (double radiance : {0.0, 1e-6, 0.01, 0.37, 5.0}) {
    const SensorExposure exposure{0.004, 2.0, 1.5};
    EXPECT_EQ(sensor.noisy_value(radiance, exposure, rng), sensor.expected_value(radiance, exposure));
  }
}

// Mean = expected value; variance = (N + read^2) / full_well^2 x gain^2 (Poisson variance N plus
// Gaussian read noise, both before the gains). Both regimes: exact Poisson (N = 20) and the
// normal approximation (N = 2000).
TEST(SensorModel, NoisyValueHasShotAndReadNoiseStatistics) {
  const SimSensor config = linear_sensor(true);
  const SensorModel sensor(config);
  const SensorExposure exposure{0.004, 2.0, 1.5};
  const double gain = exposure.analogue_gain * exposure.digital_gain;
  for (const double electrons : {20.0, 2000.0}) {
    const double radiance = electrons / (exposure.exposure_s * config.sensitivity * config.full_well_electrons);
    constexpr int n = 200'000;
    SampleRng rng(11, uint64_t(electrons));
    std::vector<double> values(n);
    for (double& v : values) v = sensor.noisy_value(radiance, exposure, rng);
    const Moments m = moments(values);

    const double read2 = config.read_noise_electrons * config.read_noise_electrons;
    const double scale = gain / config.full_well_electrons;  // value per electron
    const double sigma2 = (electrons + read2) * scale * scale;
    // Mean: 4 standard errors (false alarm ~6e-5; the seed is fixed, so this is deterministic).
    EXPECT_NEAR(m.mean, sensor.expected_value(radiance, exposure), 4 * std::sqrt(sigma2 / n)) << electrons;
    // Sample variance: its standard error is sqrt((2 sigma^4 + kappa4) / n), kappa4 = N electrons^4
    // (Poisson's fourth cumulant; the normal read noise adds none). 5 standard errors.
    const double sigma2_e = electrons + read2;
    const double se_var = std::sqrt((2 * sigma2_e * sigma2_e + electrons) / n) * scale * scale;
    EXPECT_NEAR(m.variance, sigma2, 5 * se_var) << electrons;
  }
}

// Below 50 electrons the shot noise is the exact, integer-valued Poisson distribution: with no
// read noise, the frequencies of 0..6 electrons match e^-N N^k / k!.
TEST(SensorModel, DimPixelsDrawExactPoissonCounts) {
  SimSensor config = linear_sensor(true);
  config.read_noise_electrons = 0;
  const SensorModel sensor(config);
  const SensorExposure exposure{0.01, 1.0, 1.0};
  const double mean_electrons = 2.0;
  const double radiance = mean_electrons / (exposure.exposure_s * config.sensitivity * config.full_well_electrons);
  constexpr int n = 100'000;
  std::vector<int> counts(64, 0);
  SampleRng rng(5, 9);
  for (int i = 0; i < n; ++i) {
    const double e = sensor.noisy_value(radiance, exposure, rng) * config.full_well_electrons;
    const double k = std::round(e);
    ASSERT_NEAR(e, k, 1e-9);  // whole electrons
    ASSERT_GE(k, 0);
    ++counts[std::min<size_t>(size_t(k), counts.size() - 1)];
  }
  double pmf = std::exp(-mean_electrons);
  for (int k = 0; k <= 6; ++k) {
    if (k > 0) pmf *= mean_electrons / k;
    // Binomial standard error of a frequency; 5 of them.
    EXPECT_NEAR(counts[k] / double(n), pmf, 5 * std::sqrt(pmf * (1 - pmf) / n)) << "k = " << k;
  }
}

TEST(SensorModel, NoisyValueIsDeterministicPerStream) {
  const SensorModel sensor(linear_sensor(true));
  const SensorExposure exposure{0.004, 1.0, 1.0};
  SampleRng a(42, 1);
  SampleRng b(42, 1);
  SampleRng c(42, 2);
  int differ = 0;
  for (int i = 0; i < 100; ++i) {
    const double va = sensor.noisy_value(0.3, exposure, a);
    EXPECT_EQ(va, sensor.noisy_value(0.3, exposure, b));
    differ += va != sensor.noisy_value(0.3, exposure, c);
  }
  EXPECT_GT(differ, 90);
}

TEST(SensorModel, SrgbMatchesThePublishedCurve) {
  SimSensor config;
  config.response = CameraResponse::srgb();
  const SensorModel sensor(config);
  // IEC 61966-2-1: the linear segment ends at 0.0031308 -> 12.92 x 0.0031308 = 0.040449936.
  EXPECT_NEAR(sensor.encode(0.0031308), 0.04045, 1e-6);
  EXPECT_NEAR(sensor.encode(0.001), 0.01292, 1e-12);
  // 1.055 x 0.5^(1/2.4) - 0.055 = 0.7353569831...
  EXPECT_NEAR(sensor.encode(0.5), 0.735356983, 1e-9);
  EXPECT_EQ(sensor.encode(1.0), 1.0);
  EXPECT_EQ(sensor.encode(0.0), 0.0);
  // The often quoted anchor: 8-bit sRGB 128 is linear 0.21586.
  EXPECT_NEAR(sensor.decode(128.0 / 255.0), 0.2158605, 1e-6);
  EXPECT_NEAR(sensor.decode(0.04045), 0.04045 / 12.92, 1e-15);
  EXPECT_EQ(sensor.decode(1.0), 1.0);
  // Clipping before the curve.
  EXPECT_EQ(sensor.encode(-0.5), 0.0);
  EXPECT_EQ(sensor.encode(3.0), 1.0);
  EXPECT_EQ(sensor.encode(std::nan("")), 0.0);
}

TEST(SensorModel, DecodeInvertsEncodeForEveryCurve) {
  for (const char* response : {"srgb", "linear", "gamma:2.2", "gamma:1.8"}) {
    SimSensor config;
    config.response = CameraResponse::parse(response, "sensor.response");
    const SensorModel sensor(config);
    double previous = -1;
    for (int i = 0; i <= 10000; ++i) {
      const double v = i / 10000.0;
      const double e = sensor.encode(v);
      // 1e-12: a few ulps through pow and its inverse.
      EXPECT_NEAR(sensor.decode(e), v, 1e-12) << response << " v = " << v;
      EXPECT_NEAR(sensor.encode(sensor.decode(v)), v, 1e-12) << response << " e = " << v;
      EXPECT_GT(e, previous) << response;  // strictly increasing
      previous = e;
    }
  }
}

TEST(SensorModel, GammaAndLinearCurves) {
  SimSensor config;
  config.response = CameraResponse::gamma(2.2);
  EXPECT_NEAR(SensorModel(config).encode(0.5), std::pow(0.5, 1 / 2.2), 1e-15);
  EXPECT_NEAR(SensorModel(config).decode(0.5), std::pow(0.5, 2.2), 1e-15);
  config.response = CameraResponse::linear();
  EXPECT_EQ(SensorModel(config).encode(0.3), 0.3);
  EXPECT_EQ(SensorModel(config).decode(0.3), 0.3);
}

TEST(SensorModel, QuantizeRoundsAndClampsTo8Bits) {
  EXPECT_EQ(SensorModel::quantize(0.0), 0);
  EXPECT_EQ(SensorModel::quantize(1.0), 255);
  EXPECT_EQ(SensorModel::quantize(-0.2), 0);
  EXPECT_EQ(SensorModel::quantize(1.7), 255);
  EXPECT_EQ(SensorModel::quantize(std::nan("")), 0);
  EXPECT_EQ(SensorModel::quantize(0.4999 / 255), 0);
  EXPECT_EQ(SensorModel::quantize(0.5001 / 255), 1);
  EXPECT_EQ(SensorModel::quantize(127.4999 / 255), 127);
  EXPECT_EQ(SensorModel::quantize(127.5001 / 255), 128);
  EXPECT_EQ(SensorModel::quantize(254.4999 / 255), 254);
  EXPECT_EQ(SensorModel::quantize(254.5001 / 255), 255);
  for (int k = 0; k <= 255; ++k) EXPECT_EQ(SensorModel::quantize(k / 255.0), k);
}

TEST(SensorModel, RejectsBadConfiguration) {
  for (const char* response : {"gamma:", "gamma:0", "gamma:-2", "gamma:abc", "gamma:2x", "log", "", "SRGB"}) {
    // The scene loader reads the curve through CameraResponse: it refuses these before a sensor exists.
    EXPECT_THROW(CameraResponse::parse(response, "sensor.response"), std::invalid_argument) << response;
  }
  SimSensor config;
  config.full_well_electrons = 0;
  EXPECT_THROW(SensorModel{config}, std::invalid_argument);
  config = SimSensor{};
  config.read_noise_electrons = -1;
  EXPECT_THROW(SensorModel{config}, std::invalid_argument);
}

}  // namespace
}  // namespace arpipe::sim
