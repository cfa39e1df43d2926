// The stand-in's TOML configuration: which device paths are served from which recordings, how
// (formats, pacing, timestamps) and with which faults. Keys and defaults: docs/V4L2_STANDIN.md.
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/config/choice_names.h"
#include "fault_plan.h"

namespace arpipe::standin {

// A bad configuration; what() reads "file:line:column: dotted.key: expected ..., found ..."
// (core/config/toml_section.h), or another sentence after the place.
class StandinConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class Pacing { Realtime, Fast };
inline constexpr ChoiceName<Pacing> kPacingNames[] = {{"realtime", Pacing::Realtime}, {"fast", Pacing::Fast}};
enum class TimestampBase { Recorded, Live };
inline constexpr ChoiceName<TimestampBase> kTimestampBaseNames[] = {{"recorded", TimestampBase::Recorded},
                                                                    {"live", TimestampBase::Live}};
enum class TimestampSource { StartOfExposure, EndOfFrame };
inline constexpr ChoiceName<TimestampSource> kTimestampSourceNames[] = {{"soe", TimestampSource::StartOfExposure},
                                                                        {"eof", TimestampSource::EndOfFrame}};
// A format a device offers: the recording's own, JPEG-compressed, or converted to a pixel format.
// The names ending in M are multi-planar (split planes): only with buffer_type = "mplane".
enum class OfferedFormatName { Native, Mjpg, Yuyv, Rgb24, Grey, Nv12, Uyvy, Yvyu, Nv21, Yu12, Nv16, Nv12m, Nv21m, Yuv420m, Nv16m };
inline constexpr ChoiceName<OfferedFormatName> kOfferedFormatNames[] = {
    {"native", OfferedFormatName::Native}, {"MJPG", OfferedFormatName::Mjpg},  {"YUYV", OfferedFormatName::Yuyv},
    {"RGB24", OfferedFormatName::Rgb24},   {"GREY", OfferedFormatName::Grey}, {"NV12", OfferedFormatName::Nv12},
    {"UYVY", OfferedFormatName::Uyvy},     {"YVYU", OfferedFormatName::Yvyu}, {"NV21", OfferedFormatName::Nv21},
    {"YU12", OfferedFormatName::Yu12},     {"NV16", OfferedFormatName::Nv16}, {"NV12M", OfferedFormatName::Nv12m},
    {"NV21M", OfferedFormatName::Nv21m},   {"YUV420M", OfferedFormatName::Yuv420m}, {"NV16M", OfferedFormatName::Nv16m}};
inline bool multi_planar_only(OfferedFormatName f) {
  return f == OfferedFormatName::Nv12m || f == OfferedFormatName::Nv21m || f == OfferedFormatName::Yuv420m ||
         f == OfferedFormatName::Nv16m;
}
// How buffers are described: single-planar VIDEO_CAPTURE (as UVC) or VIDEO_CAPTURE_MPLANE.
enum class BufferType { Single, Mplane };
inline constexpr ChoiceName<BufferType> kBufferTypeNames[] = {{"single", BufferType::Single}, {"mplane", BufferType::Mplane}};

struct DeviceConfig {
  std::string path;                   // absolute and lexically normal
  std::filesystem::path recording;    // absolute
  std::string card = "arpipe V4L2 stand-in";
  std::string bus_info;               // default "platform:arpipe-standin-<index>"
  std::vector<OfferedFormatName> formats = {OfferedFormatName::Native, OfferedFormatName::Mjpg};
  BufferType buffer_type = BufferType::Single;
  Pacing pacing = Pacing::Realtime;
  TimestampBase timestamps = TimestampBase::Recorded;
  TimestampSource timestamp_source = TimestampSource::StartOfExposure;
  bool loop = false;
  int jpeg_quality = 90;
  int gain_unity = 100;
  std::vector<Fault> faults;
  std::string place;          // "file:line:column" of the [[device]] table
  std::string formats_place;  // ... of its formats key (the table's when absent)
};

// A loopback fault: the output node holds its buffers for a while, as a reader that stops reading
// would on a device that waits for it (kind "stall", the only kind).
struct LoopbackStall {
  uint64_t frame = 0;        // 0-based count of frames the output node has taken since the load
  int64_t duration_ns = 0;
  std::string place;         // "file:line:column" of the [[loopback.fault]] table
};

// An output node paired with a capture node, as v4l2loopback pairs them: frames written to the
// output pass through the spool directory (so across processes) and are read from the capture node.
struct LoopbackConfig {
  std::string output;                // absolute and lexically normal
  std::string capture;               // likewise; not the output's path
  std::filesystem::path spool;       // absolute
  std::string card = "arpipe V4L2 loopback";
  std::string bus_info;              // default "platform:arpipe-loopback-<index>"
  std::vector<OfferedFormatName> formats = {OfferedFormatName::Yuyv, OfferedFormatName::Rgb24};  // raw ones only
  int max_width = 8192, max_height = 8192;  // v4l2loopback's defaults
  int64_t max_spool_bytes = int64_t(1) << 30;
  std::vector<LoopbackStall> stalls;
  std::string place;          // "file:line:column" of the [[loopback]] table
};

struct StandinConfig {
  std::vector<DeviceConfig> devices;
  std::vector<LoopbackConfig> loopbacks;
};

// Reads and checks the file (every key, type and range; unknown keys are errors). Recordings are
// not opened here. Throws StandinConfigError.
StandinConfig load_standin_config(const std::filesystem::path& file);

// The absolute, lexically normal form of a device path as the process would open it.
std::string normal_device_path(const std::string& path);

}  // namespace arpipe::standin
