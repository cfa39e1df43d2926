#include "apps/arpiped/daemon_control.h"

#include <nlohmann/json.hpp>

#include <chrono>
#include <future>

#include "capture/sinks/http/jpeg_encoder.h"
#include "capture/sinks/png_encoding.h"
#include "core/config/toml_text.h"
#include "core/pipeline/pipeline_status_json.h"

namespace arpipe {

namespace {

constexpr std::chrono::seconds kReloadAnswerTimeout{60};
constexpr int kSnapshotJpegQuality = 92;

std::string dump(const nlohmann::json& j) { return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace); }

}  // namespace

ControlReply DaemonControl::handle(const ControlRequest& request) {
  switch (request.kind) {
    case ControlRequest::Kind::Status: {
      nlohmann::json j = {{"ok", true}, {"status", pipeline_status_json(runner_.status())}};
      return {dump(j), {}};
    }
    case ControlRequest::Kind::Reload: return reload("arpipe ctl reload", {});
    case ControlRequest::Kind::Set: return reload("arpipe ctl set", request.assignments);
    case ControlRequest::Kind::Snapshot: return snapshot(request.format);
    case ControlRequest::Kind::RecordStart:
      return reload("arpipe ctl record start",
                    {"sinks.recording.enabled=true", "sinks.recording.path=" + toml_quoted(request.path)});
    case ControlRequest::Kind::RecordStop: return reload("arpipe ctl record stop", {"sinks.recording.enabled=false"});
  }
  return {dump({{"ok", false}, {"error", "unknown request"}}), {}};
}

ControlReply DaemonControl::reload(const std::string& why, std::vector<std::string> assignments) {
  auto answer = std::make_shared<std::promise<std::pair<bool, std::string>>>();
  std::future<std::pair<bool, std::string>> answered = answer->get_future();
  reloads_.start(why, std::move(assignments),
                 [answer](bool applied, const std::string& message) { answer->set_value({applied, message}); });
  if (answered.wait_for(kReloadAnswerTimeout) != std::future_status::ready)
    return {dump({{"ok", true}, {"pending", true}, {"message", "the reload is still loading (a bake?); the log will say how it ends"}}), {}};
  const auto [applied, message] = answered.get();
  return {dump({{"ok", applied}, {applied ? "message" : "error", message}}), {}};
}

ControlReply DaemonControl::snapshot(const std::string& format) {
  const std::shared_ptr<const FrameContext> frame = latest_->get();
  if (!frame || frame->output.empty()) return {dump({{"ok", false}, {"error", "no composited frame yet"}}), {}};
  const Frame& rgb = frame->output;
  std::string bytes;
  if (format == "jpg") {
    JpegEncoder encoder;
    bytes = encoder.encode(rgb, kSnapshotJpegQuality);
  } else {
    const std::vector<uint8_t> png = encode_png(rgb);
    bytes.assign(png.begin(), png.end());
  }
  nlohmann::json j = {{"ok", true},
                      {"format", format},
                      {"bytes", bytes.size()},
                      {"width", rgb.width},
                      {"height", rgb.height},
                      {"sequence", frame->camera.meta.sequence},
                      {"exposure_start_ns", frame->camera.meta.exposure_start_ns}};
  return {dump(j), std::move(bytes)};
}

}  // namespace arpipe
