// libcamera's per-request metadata as plain optional values, and its mapping to docs/DESIGN.md's
// FrameMetadata. No libcamera types here, so the mapping is tested without a camera.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include "core/config/source_choices.h"
#include "core/frame.h"

namespace arpipe {

// What a completed request's metadata said; each value is absent when the pipeline did not report
// it (UVC cameras under libcamera report little more than the timestamp).
struct LibcameraRequestValues {
  std::optional<int64_t> sensor_timestamp_ns;  // controls::SensorTimestamp
  std::optional<int64_t> exposure_us;          // controls::ExposureTime
  std::optional<double> analogue_gain;         // controls::AnalogueGain
  std::optional<double> digital_gain;          // controls::DigitalGain
  std::optional<int64_t> frame_duration_us;    // controls::FrameDuration
  std::optional<double> lux;                   // controls::Lux
  std::optional<double> colour_temperature_k;  // controls::ColourTemperature
  // What the pipeline's own processing used, reported on raw streams too: R, Gr, Gb, B at a
  // 16-bit scale (controls::SensorBlackLevels); red and blue gains (controls::ColourGains); the
  // camera-RGB-to-sRGB matrix, row-major (controls::ColourCorrectionMatrix).
  std::optional<std::array<double, 4>> sensor_black_levels_16bit;
  std::optional<std::array<double, 2>> colour_gains_rb;
  std::optional<std::array<double, 9>> colour_correction_matrix;
};

// What the config says about this camera, used where the request says nothing.
struct LibcameraTiming {
  int64_t timestamp_offset_ns = 0;     // source.timestamp_offset_ns
  int64_t readout_ns = 0;              // source.readout_ns (libcamera does not report it)
  int64_t manual_exposure_us = 0;      // source.exposure_us; 0: auto
  double manual_gain = 0;              // source.gain; 0: auto
  int64_t nominal_frame_duration_ns = 0;  // from source.fps; 0: not configured
  // source.timestamp_meaning: what SensorTimestamp means on this board (auto: as documented, the
  // first row's start of exposure; Raspberry Pi's pipeline is said to stamp its end).
  BufferTimestamps sensor_timestamp = BufferTimestamps::DriverFlag;
  // The stream's bit depth when it is raw Bayer (SensorBlackLevels is scaled to it); 0 otherwise.
  int raw_bit_depth = 0;
};
LibcameraTiming libcamera_timing(int64_t timestamp_offset_ns, int64_t readout_ns, int64_t exposure_us,
                                 double gain, double fps);

// Values the request lacked and the mapping filled in (bit flags).
enum LibcameraMissing : unsigned {
  kMissingNone = 0,
  kMissingSensorTimestamp = 1u << 0,  // took the buffer's own timestamp
  kMissingExposure = 1u << 1,         // took the manual exposure, else 0 (unknown)
  kMissingAnalogueGain = 1u << 2,     // took the manual gain, else 1
  kMissingDigitalGain = 1u << 3,      // took 1
  kMissingFrameDuration = 1u << 4,    // took the nominal duration from fps, else 0 (unknown)
};
// "SensorTimestamp, ExposureTime" for the flags set; "" for none.
std::string libcamera_missing_names(unsigned missing);

struct LibcameraMapped {
  FrameMetadata meta;
  unsigned missing = kMissingNone;  // LibcameraMissing flags
};

// Maps one completed request. `sequence` is the buffer's sequence number (gaps are drops);
// `buffer_timestamp_ns` is FrameBuffer::metadata().timestamp, used only when SensorTimestamp is
// absent, and then with the meaning TimestampMeaning::Sensor, because libcamera documents it only
// as "when the frame was captured". Lux and colour temperature stay 0 when absent (FrameMetadata's
// "unknown").
LibcameraMapped map_libcamera_metadata(const LibcameraRequestValues& values, uint64_t sequence,
                                       int64_t buffer_timestamp_ns, const LibcameraTiming& timing);

}  // namespace arpipe
