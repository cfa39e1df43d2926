// The choice keys of [source] (source.type, pacing, role, pixel_format, timestamp_meaning), each an
// enum with its one name table: the config reads them through the table, `arpipe config
// --defaults` prints them through it, and the capture code takes the typed value.
#pragma once

#include <optional>

#include "core/config/choice_names.h"
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
// RGB24 by the V4L2 source) or Auto (what the camera offers first).
enum class CaptureFormat { Auto, YUYV, NV12, RGB24, GREY, MJPG };
inline constexpr ChoiceName<CaptureFormat> kCaptureFormatNames[] = {
    {"auto", CaptureFormat::Auto}, {"YUYV", CaptureFormat::YUYV},   {"NV12", CaptureFormat::NV12},
    {"RGB24", CaptureFormat::RGB24}, {"GREY", CaptureFormat::GREY}, {"MJPG", CaptureFormat::MJPG}};

// The frame format a CaptureFormat names; nullopt for Auto and MJPG (no frame format of their own).
inline std::optional<PixelFormat> frame_format(CaptureFormat format) {
  switch (format) {
    case CaptureFormat::YUYV: return PixelFormat::YUYV;
    case CaptureFormat::NV12: return PixelFormat::NV12;
    case CaptureFormat::RGB24: return PixelFormat::RGB24;
    case CaptureFormat::GREY: return PixelFormat::GREY;
    case CaptureFormat::Auto:
    case CaptureFormat::MJPG: return std::nullopt;
  }
  return std::nullopt;
}

// What V4L2 buffer timestamps mean (source.timestamp_meaning): the driver's TSTAMP_SRC flag
// (DriverFlag, "auto"), or a fixed meaning for drivers whose flag is wrong.
enum class BufferTimestamps { DriverFlag, StartOfExposure, EndOfFrame };
inline constexpr ChoiceName<BufferTimestamps> kBufferTimestampsNames[] = {
    {"auto", BufferTimestamps::DriverFlag},
    {"start-of-exposure", BufferTimestamps::StartOfExposure},
    {"end-of-frame", BufferTimestamps::EndOfFrame}};

}  // namespace arpipe
