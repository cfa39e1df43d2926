// The choice keys of [source] (source.type, pacing, role, pixel_format, timestamp_meaning), each an
// enum with its one name table: the config reads them through the table, `arpipe config
// --defaults` prints them through it, and the capture code takes the typed value.
#pragma once

#include <optional>

#include "core/config/choice_names.h"
#include "core/frame.h"
#include "core/pixel_format.h"

namespace arpipe {

// Where the frames come from (source.type).
enum class SourceType { Replay, V4l2, Libcamera, Panorama };
inline constexpr ChoiceName<SourceType> kSourceTypeNames[] = {{"replay", SourceType::Replay},
                                                              {"v4l2", SourceType::V4l2},
                                                              {"libcamera", SourceType::Libcamera},
                                                              {"panorama", SourceType::Panorama}};

// How a replay is paced (source.pacing): by its timestamps (real time) or as fast as the pipeline runs.
enum class ReplayPacing { Timestamps, Fast };
inline constexpr ChoiceName<ReplayPacing> kReplayPacingNames[] = {{"timestamps", ReplayPacing::Timestamps},
                                                                  {"fast", ReplayPacing::Fast}};

// The libcamera stream role asked for (source.role).
enum class StreamRole { Video, Viewfinder, Still, Raw };
inline constexpr ChoiceName<StreamRole> kStreamRoleNames[] = {{"video", StreamRole::Video},
                                                              {"viewfinder", StreamRole::Viewfinder},
                                                              {"still", StreamRole::Still},
                                                              {"raw", StreamRole::Raw}};

// The pixel format asked of a live camera (source.pixel_format): a frame format, MJPG (decoded to
// RGB24 by the V4L2 source), a V4L2 format the V4L2 source reorders into a frame format as it copies
// (UYVY, YVYU, NV16 -> YUYV; NV21, YUV420 -> NV12; the "M" ones are their split-plane twins, named
// as V4L2_PIX_FMT_*), a raw Bayer format (passed on raw: core/image/bayer.h develops it), or Auto
// (what the camera offers first, formats taken as they are first).
enum class CaptureFormat {
  Auto, YUYV, NV12, RGB24, GREY, MJPG, UYVY, YVYU, NV21, YUV420, NV16, NV12M, NV21M, YUV420M, NV16M,
  SRGGB8, SBGGR8, SGRBG8, SGBRG8, SRGGB10, SBGGR10, SGRBG10, SGBRG10, SRGGB12, SBGGR12, SGRBG12, SGBRG12, SRGGB16, SBGGR16, SGRBG16, SGBRG16, SRGGB10P, SBGGR10P, SGRBG10P, SGBRG10P, SRGGB12P, SBGGR12P, SGRBG12P, SGBRG12P
};
inline constexpr ChoiceName<CaptureFormat> kCaptureFormatNames[] = {
    {"auto", CaptureFormat::Auto},     {"YUYV", CaptureFormat::YUYV},   {"NV12", CaptureFormat::NV12},
    {"RGB24", CaptureFormat::RGB24},   {"GREY", CaptureFormat::GREY},   {"MJPG", CaptureFormat::MJPG},
    {"UYVY", CaptureFormat::UYVY},     {"YVYU", CaptureFormat::YVYU},   {"NV21", CaptureFormat::NV21},
    {"YUV420", CaptureFormat::YUV420}, {"NV16", CaptureFormat::NV16},   {"NV12M", CaptureFormat::NV12M},
    {"NV21M", CaptureFormat::NV21M},   {"YUV420M", CaptureFormat::YUV420M}, {"NV16M", CaptureFormat::NV16M},
    {"SRGGB8", CaptureFormat::SRGGB8}, {"SBGGR8", CaptureFormat::SBGGR8}, {"SGRBG8", CaptureFormat::SGRBG8}, {"SGBRG8", CaptureFormat::SGBRG8},
    {"SRGGB10", CaptureFormat::SRGGB10}, {"SBGGR10", CaptureFormat::SBGGR10}, {"SGRBG10", CaptureFormat::SGRBG10}, {"SGBRG10", CaptureFormat::SGBRG10},
    {"SRGGB12", CaptureFormat::SRGGB12}, {"SBGGR12", CaptureFormat::SBGGR12}, {"SGRBG12", CaptureFormat::SGRBG12}, {"SGBRG12", CaptureFormat::SGBRG12},
    {"SRGGB16", CaptureFormat::SRGGB16}, {"SBGGR16", CaptureFormat::SBGGR16}, {"SGRBG16", CaptureFormat::SGRBG16}, {"SGBRG16", CaptureFormat::SGBRG16},
    {"SRGGB10P", CaptureFormat::SRGGB10P}, {"SBGGR10P", CaptureFormat::SBGGR10P}, {"SGRBG10P", CaptureFormat::SGRBG10P}, {"SGBRG10P", CaptureFormat::SGBRG10P},
    {"SRGGB12P", CaptureFormat::SRGGB12P}, {"SBGGR12P", CaptureFormat::SBGGR12P}, {"SGRBG12P", CaptureFormat::SGRBG12P}, {"SGBRG12P", CaptureFormat::SGBRG12P},
};

// The frame format a CaptureFormat names (the four frame formats and the Bayer ones, by name);
// nullopt for Auto, MJPG and the formats only the V4L2 source reorders.
inline std::optional<PixelFormat> frame_format(CaptureFormat format) {
  if (format == CaptureFormat::Auto || format == CaptureFormat::MJPG) return std::nullopt;
  return pixel_format_from_name(choice_name(kCaptureFormatNames, format));
}

// What a live camera's timestamps mean (source.timestamp_meaning): what the camera says
// (DriverFlag, "auto": V4L2's TSTAMP_SRC flag; libcamera's SensorTimestamp as documented, the first
// row's start of exposure), or a fixed meaning for drivers that say wrong: the first row's start or
// end of exposure, or the last row's end of readout.
enum class BufferTimestamps { DriverFlag, StartOfExposure, EndOfExposure, EndOfFrame };
inline constexpr ChoiceName<BufferTimestamps> kBufferTimestampsNames[] = {
    {"auto", BufferTimestamps::DriverFlag},
    {"start-of-exposure", BufferTimestamps::StartOfExposure},
    {"end-of-exposure", BufferTimestamps::EndOfExposure},
    {"end-of-frame", BufferTimestamps::EndOfFrame}};

// The meaning a configured value fixes; nullopt for "auto" (what the camera says).
inline std::optional<TimestampMeaning> fixed_timestamp_meaning(BufferTimestamps configured) {
  switch (configured) {
    case BufferTimestamps::DriverFlag: return std::nullopt;
    case BufferTimestamps::StartOfExposure: return TimestampMeaning::StartOfExposure;
    case BufferTimestamps::EndOfExposure: return TimestampMeaning::EndOfExposure;
    case BufferTimestamps::EndOfFrame: return TimestampMeaning::EndOfFrame;
  }
  return std::nullopt;
}

}  // namespace arpipe
