// The mapping of libcamera request metadata to FrameMetadata, against values worked out by hand
// from the control definitions (µs for ExposureTime and FrameDuration, ns for SensorTimestamp).
// All quantities are integers or exactly representable, so the comparisons are exact.
#include <gtest/gtest.h>

#include <array>

#include "capture/libcamera/libcamera_metadata.h"

namespace arpipe {
namespace {

LibcameraRequestValues full_values() {
  LibcameraRequestValues v;
  v.sensor_timestamp_ns = 5'000'123'456'789;
  v.exposure_us = 12'345;
  v.analogue_gain = 2.5;
  v.digital_gain = 1.25;
  v.frame_duration_us = 33'333;
  v.lux = 412.5;
  v.colour_temperature_k = 5600;
  return v;
}

TEST(LibcameraMetadata, EveryValuePresentMapsExactly) {
  const auto timing = libcamera_timing(/*offset*/ -1'500'000, /*readout*/ 18'000'000, 0, 0, 30);
  const auto r = map_libcamera_metadata(full_values(), 77, /*buffer timestamp*/ 999, timing);
  EXPECT_EQ(r.missing, kMissingNone);
  const FrameMetadata& m = r.meta;
  EXPECT_EQ(m.sequence, 77u);
  EXPECT_EQ(m.raw_timestamp_ns, 5'000'123'456'789);
  EXPECT_EQ(m.raw_timestamp_meaning, TimestampMeaning::StartOfExposure);
  // SensorTimestamp is the start of exposure: only the configured offset is added.
  EXPECT_EQ(m.exposure_start_ns, 5'000'123'456'789 - 1'500'000);
  EXPECT_EQ(m.timestamp_offset_ns, -1'500'000);
  EXPECT_EQ(m.exposure_ns, 12'345'000);
  EXPECT_EQ(m.readout_ns, 18'000'000);
  EXPECT_EQ(m.frame_duration_ns, 33'333'000);  // the request's, not the nominal 33'333'333
  EXPECT_EQ(m.analogue_gain, 2.5);
  EXPECT_EQ(m.digital_gain, 1.25);
  EXPECT_EQ(m.lux, 412.5);
  EXPECT_EQ(m.colour_temperature_k, 5600);
}

// A raw stream's development (core/raw_colour.h): SensorBlackLevels is at a 16-bit scale (4096
// is 256 at 12 bits, 64 at 10), ColourGains are red and blue (green 1), the matrix passes as is.
// A processed stream's frames carry none of it: its pixels are developed already.
TEST(LibcameraMetadata, RawStreamsCarryTheirBlackLevelsGainsAndMatrix) {
  LibcameraRequestValues v = full_values();
  v.sensor_black_levels_16bit = std::array<double, 4>{4096, 4096, 4160, 4032};
  v.colour_gains_rb = std::array<double, 2>{1.75, 2.5};
  v.colour_correction_matrix = std::array<double, 9>{1.5, -0.25, -0.25, -0.125, 1.25, -0.125, 0, -0.5, 1.5};
  LibcameraTiming timing = libcamera_timing(0, 0, 0, 0, 30);
  timing.raw_bit_depth = 10;
  const FrameMetadata m = map_libcamera_metadata(v, 1, 0, timing).meta;
  ASSERT_TRUE(m.raw.black_level && m.raw.gains && m.raw.colour_matrix);
  EXPECT_EQ(*m.raw.black_level, (std::array<double, 4>{64, 64, 65, 63}));
  EXPECT_EQ(*m.raw.gains, (std::array<double, 3>{1.75, 1, 2.5}));
  EXPECT_EQ(*m.raw.colour_matrix, *v.colour_correction_matrix);
  timing.raw_bit_depth = 12;
  EXPECT_EQ(*map_libcamera_metadata(v, 1, 0, timing).meta.raw.black_level, (std::array<double, 4>{256, 256, 260, 252}));
  timing.raw_bit_depth = 0;
  EXPECT_EQ(map_libcamera_metadata(v, 1, 0, timing).meta.raw, RawColour{});
}

// source.timestamp_meaning settles what a board's SensorTimestamp means without a rebuild
// (docs/OPERATIONS.md, "What the timestamp means on this board"): the first row's end of exposure
// is one exposure after its start; the last row's end of readout one exposure and one readout.
TEST(LibcameraMetadata, TheConfiguredMeaningOfSensorTimestampGivesTheExposureStart) {
  const int64_t raw = 5'000'123'456'789, exposure = 12'345'000, readout = 18'000'000, offset = -1'500'000;
  const std::pair<BufferTimestamps, int64_t> cases[] = {
      {BufferTimestamps::DriverFlag, raw + offset},
      {BufferTimestamps::StartOfExposure, raw + offset},
      {BufferTimestamps::EndOfExposure, raw - exposure + offset},
      {BufferTimestamps::EndOfFrame, raw - exposure - readout + offset}};
  for (const auto& [configured, start] : cases) {
    auto timing = libcamera_timing(offset, readout, 0, 0, 30);
    timing.sensor_timestamp = configured;
    const auto r = map_libcamera_metadata(full_values(), 1, 999, timing);
    EXPECT_EQ(r.meta.raw_timestamp_ns, raw);
    EXPECT_EQ(r.meta.exposure_start_ns, start) << choice_name(kBufferTimestampsNames, configured);
  }
}

TEST(LibcameraMetadata, MissingSensorTimestampFallsBackToTheBufferTimestampAsSensorTime) {
  auto v = full_values();
  v.sensor_timestamp_ns.reset();
  const auto r = map_libcamera_metadata(v, 3, 7'000'000'000, libcamera_timing(250'000, 0, 0, 0, 0));
  EXPECT_EQ(r.missing, kMissingSensorTimestamp);
  EXPECT_EQ(r.meta.raw_timestamp_ns, 7'000'000'000);
  EXPECT_EQ(r.meta.raw_timestamp_meaning, TimestampMeaning::Sensor);
  // "Sensor" is treated as start of exposure plus the offset (core/frame.h).
  EXPECT_EQ(r.meta.exposure_start_ns, 7'000'250'000);
  EXPECT_EQ(libcamera_missing_names(r.missing), "SensorTimestamp");
}

TEST(LibcameraMetadata, MissingExposureAndGainTakeTheManualConfigValues) {
  LibcameraRequestValues v;
  v.sensor_timestamp_ns = 1'000;
  const auto r = map_libcamera_metadata(v, 0, 0, libcamera_timing(0, 0, /*exposure_us*/ 8'000, /*gain*/ 4.0, /*fps*/ 50));
  EXPECT_EQ(r.missing, kMissingExposure | kMissingAnalogueGain | kMissingDigitalGain | kMissingFrameDuration);
  EXPECT_EQ(r.meta.exposure_ns, 8'000'000);
  EXPECT_EQ(r.meta.analogue_gain, 4.0);
  EXPECT_EQ(r.meta.digital_gain, 1.0);
  EXPECT_EQ(r.meta.frame_duration_ns, 20'000'000);  // 1 s / 50
  EXPECT_EQ(r.meta.exposure_start_ns, 1'000);
  EXPECT_EQ(libcamera_missing_names(r.missing), "ExposureTime, AnalogueGain, DigitalGain, FrameDuration");
}

TEST(LibcameraMetadata, MissingValuesUnderAutoExposureAreUnknownOrUnity) {
  LibcameraRequestValues v;  // nothing at all, as from a pipeline that reports nothing
  const auto r = map_libcamera_metadata(v, 9, 42, libcamera_timing(0, 0, 0, 0, 0));
  EXPECT_EQ(r.meta.exposure_ns, 0);        // unknown
  EXPECT_EQ(r.meta.frame_duration_ns, 0);  // unknown
  EXPECT_EQ(r.meta.analogue_gain, 1.0);
  EXPECT_EQ(r.meta.digital_gain, 1.0);
  EXPECT_EQ(r.meta.lux, 0.0);
  EXPECT_EQ(r.meta.colour_temperature_k, 0.0);
  EXPECT_EQ(r.meta.exposure_start_ns, 42);
}

TEST(LibcameraMetadata, TimingRoundsTheNominalFrameDuration) {
  EXPECT_EQ(libcamera_timing(0, 0, 0, 0, 30).nominal_frame_duration_ns, 33'333'333);
  EXPECT_EQ(libcamera_timing(0, 0, 0, 0, 29.97).nominal_frame_duration_ns, 33'366'700);  // 1e9/29.97 = 33366700.03
  EXPECT_EQ(libcamera_timing(0, 0, -5, -1, -2).manual_exposure_us, 0);
}

}  // namespace
}  // namespace arpipe
