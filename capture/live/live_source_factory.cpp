// make_live_source: the config's source.type picks the backend; both share LiveSource's reconnects.
#include <fmt/format.h>

#include "capture/libcamera/libcamera_stream.h"
#include "capture/live/live_source.h"
#include "capture/v4l2/v4l2_stream.h"
#include "core/config/config.h"

namespace arpipe {

std::unique_ptr<LiveSource> make_live_source(const SourceConfig& config) {
  std::shared_ptr<const CameraModel> model;
  if (!config.camera_model.empty()) model = std::make_shared<const CameraModel>(CameraModel::load(config.camera_model));
  ReconnectPolicy policy;
  policy.frame_timeout_ns = config.frame_timeout_ms * 1'000'000;
  policy.first_retry_ns = config.reconnect_min_ms * 1'000'000;
  policy.max_retry_ns = config.reconnect_max_ms * 1'000'000;
  if (config.type == SourceType::V4l2) {
    if (config.device.empty())
      throw CameraError(CameraError::Kind::Refused, "source.type is \"v4l2\" but source.device is not set");
    const V4L2StreamSettings settings = v4l2_stream_settings(config);
    return std::make_unique<LiveSource>(fmt::format("v4l2:{}", config.device),
                                        [settings] { return open_v4l2_stream(settings); }, model, policy);
  }
  if (config.type == SourceType::Libcamera) {
    const std::string name = fmt::format("libcamera:{}", config.camera.empty() ? "0" : config.camera);
    return std::make_unique<LiveSource>(name, [config] { return open_libcamera_stream(config); }, model, policy);
  }
  throw CameraError(CameraError::Kind::Refused,
                    fmt::format("source.type \"{}\" is not a live camera", choice_name(kSourceTypeNames, config.type)));
}

}  // namespace arpipe
