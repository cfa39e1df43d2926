// Frame timing and auto-exposure of the simulated camera: exact integer frame starts, raw
// timestamps that normalise back exactly (docs/DESIGN.md "Time"), and an AE loop that converges
// within its limits.
#include "capture/sim/exposure_control.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

namespace arpipe::sim {
namespace {

SimCamera camera_at(double fps) {
  SimCamera camera;
  camera.fps = fps;
  camera.first_exposure_start_ns = 5'000'000'123;
  return camera;
}

TEST(ExposureControl, MetadataRoundTripsThroughTheRawTimestamp) {
  for (const TimestampMeaning meaning :
       {TimestampMeaning::StartOfExposure, TimestampMeaning::EndOfFrame, TimestampMeaning::EndOfExposure,
        TimestampMeaning::Sensor}) {
    for (const int64_t offset : {int64_t(-7'654'321), int64_t(12'345'678)}) {
      SimCamera camera = camera_at(30);
      camera.timestamp_meaning = meaning;
      camera.timestamp_offset_ns = offset;
      camera.readout_ns = 15'000'000;
      const ExposureSetting setting{8'000'000, 2.5, 1.25};
      for (const uint64_t sequence : {uint64_t(0), uint64_t(1), uint64_t(2), uint64_t(997)}) {
        const FrameMetadata meta = simulated_frame_metadata(camera, sequence, setting);
        const int64_t start = camera.first_exposure_start_ns + std::llround(sequence * 1e9 / 30);
        EXPECT_EQ(meta.exposure_start_ns, start);
        EXPECT_EQ(meta.sequence, sequence);
        EXPECT_EQ(meta.exposure_ns, 8'000'000);
        EXPECT_EQ(meta.readout_ns, 15'000'000);
        EXPECT_EQ(meta.frame_duration_ns, 33'333'333);
        EXPECT_EQ(meta.analogue_gain, 2.5);
        EXPECT_EQ(meta.digital_gain, 1.25);
        EXPECT_EQ(meta.raw_timestamp_meaning, meaning);
        EXPECT_EQ(meta.timestamp_offset_ns, offset);
        // What the driver stamps: the last row's end for end-of-frame, the first row's end for
        // end-of-exposure, else the first row's start, on a clock `offset` behind ours.
        const int64_t raw = meaning == TimestampMeaning::EndOfFrame      ? start - offset + 8'000'000 + 15'000'000
                            : meaning == TimestampMeaning::EndOfExposure ? start - offset + 8'000'000
                                                                         : start - offset;
        EXPECT_EQ(meta.raw_timestamp_ns, raw);
        EXPECT_EQ(exposure_start_from_raw(meta.raw_timestamp_ns, meta.raw_timestamp_meaning, meta.exposure_ns,
                                          meta.readout_ns, meta.timestamp_offset_ns),
                  meta.exposure_start_ns);
      }
    }
  }
}

// round(k * 1e9 / 30) = (2 k 1e9 + 30) / 60 in integers: intervals are 33333333 or 33333334 ns,
// every third start lands on a whole 1e8 ns, and nothing drifts over a million frames.
TEST(ExposureControl, FrameStartsAreExactAt30Fps) {
  const SimCamera camera = camera_at(30);
  const ExposureSetting setting{4'000'000, 1, 1};
  int64_t previous = simulated_frame_metadata(camera, 0, setting).exposure_start_ns;
  EXPECT_EQ(previous, camera.first_exposure_start_ns);
  for (int64_t k = 1; k <= 1'000'000; ++k) {
    const int64_t start = simulated_frame_metadata(camera, uint64_t(k), setting).exposure_start_ns;
    ASSERT_EQ(start - camera.first_exposure_start_ns, (2 * k * 1'000'000'000 + 30) / 60) << k;
    const int64_t interval = start - previous;
    ASSERT_TRUE(interval == 33'333'333 || interval == 33'333'334) << k;
    // Pattern 33333333, 33333334, 33333333 (k = 1, 2, 3 mod 3).
    ASSERT_EQ(interval, k % 3 == 2 ? 33'333'334 : 33'333'333) << k;
    previous = start;
  }
  EXPECT_EQ(simulated_frame_metadata(camera, 3'000'000, setting).exposure_start_ns - camera.first_exposure_start_ns,
            100'000'000'000'000);
  // Far beyond double precision of k * 1e9 / 30 (3e9 frames: 1e17 ns), still exact.
  EXPECT_EQ(simulated_frame_metadata(camera, 3'000'000'000, setting).exposure_start_ns -
                camera.first_exposure_start_ns,
            100'000'000'000'000'000);
}

TEST(ExposureControl, FrameStartsAreExactAtNtscAndOtherRates) {
  const ExposureSetting setting{1'000'000, 1, 1};
  // 29.97 = 30000/1001: frame 30000 starts exactly 1001 s later; the interval is 33366667 ns.
  const SimCamera ntsc = camera_at(30000.0 / 1001.0);
  EXPECT_EQ(simulated_frame_metadata(ntsc, 30000, setting).exposure_start_ns - ntsc.first_exposure_start_ns,
            1'001'000'000'000);
  EXPECT_EQ(simulated_frame_metadata(ntsc, 1, setting).exposure_start_ns - ntsc.first_exposure_start_ns, 33'366'667);
  EXPECT_EQ(simulated_frame_metadata(ntsc, 0, setting).frame_duration_ns, 33'366'667);
  for (const double fps : {25.0, 60.0, 90.0, 7.5}) {
    const SimCamera camera = camera_at(fps);
    for (const uint64_t k : {uint64_t(1), uint64_t(12345), uint64_t(1'000'000)})
      EXPECT_EQ(simulated_frame_metadata(camera, k, setting).exposure_start_ns - camera.first_exposure_start_ns,
                std::llround(double(k) * 1e9 / fps))
          << fps;
  }
}

TEST(ExposureControl, RowsStartEvenlyOverTheReadout) {
  FrameMetadata meta;
  meta.readout_ns = 24'000'000;
  EXPECT_EQ(row_exposure_start_s(meta, 0, 481), 0.0);
  EXPECT_NEAR(row_exposure_start_s(meta, 480, 481), 0.024, 1e-15);
  EXPECT_NEAR(row_exposure_start_s(meta, 240, 481), 0.012, 1e-15);
  EXPECT_NEAR(row_exposure_start_s(meta, 1, 481), 0.024 / 480, 1e-18);
  EXPECT_EQ(row_exposure_start_s(meta, 0, 1), 0.0);  // one row: no skew
  meta.readout_ns = 0;                                // global shutter
  EXPECT_EQ(row_exposure_start_s(meta, 479, 480), 0.0);
}

TEST(ExposureControl, FixedScheduleCyclesAndIgnoresFeedback) {
  SimCamera camera = camera_at(30);
  camera.exposure_ns = {1'000'000, 2'000'000, 3'000'000};
  camera.analogue_gain = 2;
  camera.digital_gain = 1.5;
  ExposureControl control(camera);
  for (uint64_t k = 0; k < 10; ++k) {
    const ExposureSetting s = control.setting(k);
    EXPECT_EQ(s.exposure_ns, camera.exposure_ns[k % 3]);
    EXPECT_EQ(s.analogue_gain, 2);
    EXPECT_EQ(s.digital_gain, 1.5);
    control.update(0.9);  // no auto-exposure: no effect
  }
}

// A constant linear scene: the frame's mean is proportional to exposure x analogue x digital gain.
double scene_mean(double brightness_per_s, const ExposureSetting& s) {
  return brightness_per_s * (double(s.exposure_ns) * 1e-9) * s.analogue_gain * s.digital_gain;
}

SimCamera auto_camera() {
  SimCamera camera = camera_at(30);
  camera.exposure_ns = {4'000'000};
  camera.auto_exposure.enabled = true;
  camera.auto_exposure.target = 0.18;
  camera.auto_exposure.min_exposure_ns = 100'000;
  camera.auto_exposure.max_gain = 8;
  return camera;
}

TEST(ExposureControl, AutoExposureConvergesOnAConstantScene) {
  const SimCamera camera = auto_camera();
  // At 4 ms the scene gives 0.01: it needs x18 = 72 ms, more than the 33.3 ms frame interval, so
  // exposure saturates and the analogue gain makes up 2.16. x4 per frame: ceil(log4 18) = 3 frames.
  const double brightness = 0.01 / 0.004;
  ExposureControl control(camera);
  EXPECT_EQ(control.setting(0).exposure_ns, 4'000'000);
  EXPECT_EQ(control.setting(0).analogue_gain, 1.0);
  for (uint64_t k = 0; k < 10; ++k) {
    const ExposureSetting s = control.setting(k);
    const double mean = scene_mean(brightness, s);
    if (k < 3) {
      EXPECT_LT(mean, 0.9 * camera.auto_exposure.target) << k;  // still limited by the x4 clamp
    } else {
      // Exposure and gain are set so exposure x gain lands on the target; 1e-9 covers rounding.
      EXPECT_NEAR(mean, camera.auto_exposure.target, 1e-9) << k;
      EXPECT_EQ(s.exposure_ns, 33'333'333);
      EXPECT_NEAR(s.analogue_gain, 0.072 / 0.033333333, 1e-6);
    }
    control.update(mean);
  }
}

TEST(ExposureControl, AutoExposureStaysWithinItsLimits) {
  const SimCamera camera = auto_camera();
  for (const double brightness : {1e-3, 1e6}) {  // far too dark, far too bright
    ExposureControl control(camera);
    ExposureSetting last = control.setting(0);
    for (uint64_t k = 0; k < 40; ++k) {
      const ExposureSetting s = control.setting(k);
      EXPECT_GE(s.exposure_ns, camera.auto_exposure.min_exposure_ns);
      EXPECT_LE(s.exposure_ns, 33'333'333);
      EXPECT_GE(s.analogue_gain, 1.0);
      EXPECT_LE(s.analogue_gain, camera.auto_exposure.max_gain);
      EXPECT_EQ(s.digital_gain, camera.digital_gain);
      // Never more than x4 or /4 per frame (1e-9: whole-ns rounding of the exposure).
      const double step = (double(s.exposure_ns) * s.analogue_gain) / (double(last.exposure_ns) * last.analogue_gain);
      EXPECT_LE(step, 4 * (1 + 1e-9));
      EXPECT_GE(step, 0.25 * (1 - 1e-9));
      // Gain is only used once the exposure is as long as the frame allows.
      if (s.analogue_gain > 1) {
        EXPECT_EQ(s.exposure_ns, 33'333'333);
      }
      last = s;
      control.update(scene_mean(brightness, s));
    }
    if (brightness < 1) {
      EXPECT_EQ(last.exposure_ns, 33'333'333);
      EXPECT_EQ(last.analogue_gain, 8.0);
    } else {
      EXPECT_EQ(last.exposure_ns, 100'000);
      EXPECT_EQ(last.analogue_gain, 1.0);
    }
  }
}

TEST(ExposureControl, AutoExposureLowersGainBeforeExposure) {
  const SimCamera camera = auto_camera();
  ExposureControl control(camera);
  for (uint64_t k = 0; k < 10; ++k) control.update(scene_mean(1e-3, control.setting(k)));  // dark: max everything
  ASSERT_EQ(control.setting(10).analogue_gain, 8.0);
  // The scene brightens: the mean is twice the target, so gain halves and exposure stays.
  control.update(2 * camera.auto_exposure.target);
  EXPECT_EQ(control.setting(11).exposure_ns, 33'333'333);
  EXPECT_NEAR(control.setting(11).analogue_gain, 4.0, 1e-12);
  // Eight times too bright: gain goes to 1 (x1/4 clamp: 4 -> 1), exposure still untouched.
  control.update(8 * camera.auto_exposure.target);
  EXPECT_EQ(control.setting(12).exposure_ns, 33'333'333);
  EXPECT_EQ(control.setting(12).analogue_gain, 1.0);
  // Only now does exposure shorten.
  control.update(2 * camera.auto_exposure.target);
  EXPECT_EQ(control.setting(13).exposure_ns, 16'666'667);
  EXPECT_EQ(control.setting(13).analogue_gain, 1.0);
}

TEST(ExposureControl, BlackOrInvalidFeedbackOpensUpByFour) {
  const SimCamera camera = auto_camera();
  for (const double mean : {0.0, -0.5, std::nan("")}) {
    ExposureControl control(camera);
    control.update(mean);
    EXPECT_EQ(control.setting(1).exposure_ns, 16'000'000) << mean;
    EXPECT_EQ(control.setting(1).analogue_gain, 1.0) << mean;
  }
}

TEST(ExposureControl, RejectsBadCameras) {
  SimCamera camera = camera_at(0);
  EXPECT_THROW(ExposureControl{camera}, std::invalid_argument);
  camera = camera_at(30);
  camera.exposure_ns.clear();
  EXPECT_THROW(ExposureControl{camera}, std::invalid_argument);
  camera.exposure_ns = {4'000'000, 0};
  EXPECT_THROW(ExposureControl{camera}, std::invalid_argument);
  camera = auto_camera();
  camera.auto_exposure.min_exposure_ns = 0;
  EXPECT_THROW(ExposureControl{camera}, std::invalid_argument);
}

}  // namespace
}  // namespace arpipe::sim
