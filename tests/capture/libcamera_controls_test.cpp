// Reading libcamera ControlLists into arpipe values and building the start-up controls, with
// ControlLists and ControlInfoMaps made by hand (no camera). Values are exact by construction.
#include <gtest/gtest.h>

#include <array>

#include <libcamera/control_ids.h>
#include <libcamera/version.h>

#include "capture/libcamera/libcamera_controls.h"

namespace arpipe {
namespace {

namespace c = libcamera::controls;

TEST(LibcameraControls, RequestMetadataMapsExactly) {
  libcamera::ControlList md(c::controls);
  md.set(c::SensorTimestamp, int64_t{1'234'567'890'123});
  md.set(c::ExposureTime, int32_t{10'000});
  md.set(c::AnalogueGain, 3.0f);
  md.set(c::DigitalGain, 1.5f);
  md.set(c::FrameDuration, int64_t{16'667});
  md.set(c::Lux, 250.0f);
  md.set(c::ColourTemperature, int32_t{4500});

  const auto v = read_request_values(md);
  ASSERT_TRUE(v.sensor_timestamp_ns && v.exposure_us && v.analogue_gain && v.digital_gain && v.frame_duration_us &&
              v.lux && v.colour_temperature_k);
  const auto r = map_libcamera_metadata(v, 12, 0, libcamera_timing(/*offset*/ 2'000, /*readout*/ 10'000'000, 0, 0, 60));
  EXPECT_EQ(r.missing, kMissingNone);
  EXPECT_EQ(r.meta.sequence, 12u);
  EXPECT_EQ(r.meta.raw_timestamp_ns, 1'234'567'890'123);
  EXPECT_EQ(r.meta.raw_timestamp_meaning, TimestampMeaning::StartOfExposure);
  EXPECT_EQ(r.meta.exposure_start_ns, 1'234'567'892'123);
  EXPECT_EQ(r.meta.exposure_ns, 10'000'000);
  EXPECT_EQ(r.meta.readout_ns, 10'000'000);
  EXPECT_EQ(r.meta.frame_duration_ns, 16'667'000);
  EXPECT_EQ(r.meta.analogue_gain, 3.0);
  EXPECT_EQ(r.meta.digital_gain, 1.5);
  EXPECT_EQ(r.meta.lux, 250.0);
  EXPECT_EQ(r.meta.colour_temperature_k, 4500.0);
}

TEST(LibcameraControls, RawDevelopmentMetadataIsRead) {
  libcamera::ControlList md(c::controls);
  md.set(c::SensorBlackLevels, libcamera::Span<const int32_t, 4>(std::array<int32_t, 4>{4096, 4100, 4104, 4108}));
  md.set(c::ColourGains, libcamera::Span<const float, 2>(std::array<float, 2>{1.5f, 2.25f}));
  const std::array<float, 9> ccm{1.5f, -0.25f, -0.25f, -0.125f, 1.25f, -0.125f, 0.0f, -0.5f, 1.5f};
  md.set(c::ColourCorrectionMatrix, libcamera::Span<const float, 9>(ccm));
  const auto v = read_request_values(md);
  ASSERT_TRUE(v.sensor_black_levels_16bit && v.colour_gains_rb && v.colour_correction_matrix);
  EXPECT_EQ(*v.sensor_black_levels_16bit, (std::array<double, 4>{4096, 4100, 4104, 4108}));
  EXPECT_EQ(*v.colour_gains_rb, (std::array<double, 2>{1.5, 2.25}));
  for (size_t i = 0; i < 9; ++i) EXPECT_EQ((*v.colour_correction_matrix)[i], double(ccm[i])) << i;
}

TEST(LibcameraControls, AbsentControlsStayAbsent) {
  libcamera::ControlList md(c::controls);
  md.set(c::SensorTimestamp, int64_t{77});
  const auto v = read_request_values(md);
  EXPECT_EQ(v.sensor_timestamp_ns, 77);
  EXPECT_FALSE(v.exposure_us || v.analogue_gain || v.digital_gain || v.frame_duration_us || v.lux ||
               v.colour_temperature_k);
  const auto r = map_libcamera_metadata(v, 0, 5, libcamera_timing(-7, 0, 0, 0, 0));
  EXPECT_EQ(r.meta.exposure_start_ns, 70);  // the sensor timestamp, not the buffer's, plus the offset
}

// Ranges like a Raspberry Pi IMX708's (ExposureTime in µs, FrameDurationLimits in µs).
libcamera::ControlInfoMap pi_like_controls(bool with_frame_duration) {
  libcamera::ControlInfoMap::Map map;
  map.emplace(&c::AeEnable, libcamera::ControlInfo(false, true));
  map.emplace(&c::ExposureTime, libcamera::ControlInfo(int32_t{26}, int32_t{112'015'553}, int32_t{20'000}));
  map.emplace(&c::AnalogueGain, libcamera::ControlInfo(1.0f, 16.0f, 1.0f));
  if (with_frame_duration)
    map.emplace(&c::FrameDurationLimits, libcamera::ControlInfo(int64_t{8'333}, int64_t{112'017'347}, int64_t{33'333}));
  return libcamera::ControlInfoMap(std::move(map), c::controls);
}

TEST(LibcameraControls, ManualExposureGainAndRate) {
  SourceConfig config;
  config.exposure_us = 5'000;
  config.gain = 2.0;
  config.fps = 30;
  const auto s = build_start_controls(config, pi_like_controls(true));
  EXPECT_TRUE(s.refused.empty());
  EXPECT_TRUE(s.notes.empty());
  EXPECT_EQ(s.controls.get(c::ExposureTime), 5'000);
  EXPECT_EQ(s.controls.get(c::AnalogueGain), 2.0f);
#if LIBCAMERA_VERSION_MAJOR == 0 && LIBCAMERA_VERSION_MINOR < 5
  EXPECT_EQ(s.controls.get(c::AeEnable), false);  // both fixed: the AE has nothing left to do
#endif
  auto limits = s.controls.get(c::FrameDurationLimits);
  ASSERT_TRUE(limits);
  EXPECT_EQ((*limits)[0], 33'333);  // round(1e6 / 30) µs, both limits: a fixed rate
  EXPECT_EQ((*limits)[1], 33'333);
}

TEST(LibcameraControls, ExposureAloneLeavesTheAeOnForTheGain) {
  SourceConfig config;
  config.exposure_us = 5'000;
  const auto s = build_start_controls(config, pi_like_controls(true));
  EXPECT_TRUE(s.refused.empty());
  EXPECT_EQ(s.controls.get(c::ExposureTime), 5'000);
  EXPECT_FALSE(s.controls.get(c::AnalogueGain));
  EXPECT_FALSE(s.controls.get(c::AeEnable));
  EXPECT_FALSE(s.controls.get(c::FrameDurationLimits));
}

TEST(LibcameraControls, AutoSetsNothing) {
  const auto s = build_start_controls(SourceConfig{}, pi_like_controls(true));
  EXPECT_TRUE(s.controls.empty());
  EXPECT_TRUE(s.refused.empty());
}

TEST(LibcameraControls, OutOfRangeIsRefusedNamingTheRange) {
  SourceConfig config;
  config.gain = 32;
  config.fps = 200;  // 5000 µs < the 8333 µs minimum frame duration
  const auto s = build_start_controls(config, pi_like_controls(true));
  ASSERT_EQ(s.refused.size(), 2u);
  EXPECT_NE(s.refused[0].find("AnalogueGain 32"), std::string::npos) << s.refused[0];
  EXPECT_NE(s.refused[1].find("FrameDurationLimits 5000"), std::string::npos) << s.refused[1];
  EXPECT_NE(s.refused[1].find("8333"), std::string::npos) << s.refused[1];
}

TEST(LibcameraControls, AbsentRateControlIsANoteAndAbsentExposureControlARefusal) {
  SourceConfig config;
  config.fps = 30;
  auto s = build_start_controls(config, pi_like_controls(false));
  EXPECT_TRUE(s.refused.empty());
  ASSERT_EQ(s.notes.size(), 1u);
  EXPECT_FALSE(s.controls.get(c::FrameDurationLimits));

  config.exposure_us = 1000;
  s = build_start_controls(config, libcamera::ControlInfoMap(libcamera::ControlInfoMap::Map{}, c::controls));
  ASSERT_EQ(s.refused.size(), 1u);
  EXPECT_NE(s.refused[0].find("no ExposureTime control"), std::string::npos) << s.refused[0];
}

}  // namespace
}  // namespace arpipe
