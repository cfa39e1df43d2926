#include "capture/sinks/results_sink.h"

#include <fmt/format.h>

#include <cerrno>
#include <cstring>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "core/log.h"

namespace arpipe {

ResultsSink::ResultsSink(const ResultsSinkConfig& config)
    : path_(config.path),
      file_(path_, "sinks.results.path"),
      outage_(path_.string(), "the file ends at its last complete line") {}

// Never committed (the start failed): OutputFile removes this run's file and the previous one stays.
ResultsSink::~ResultsSink() { outage_.report_at_end(); }

void ResultsSink::run_started() noexcept {
  std::string error;
  if (!file_.committed() && !file_.commit(error))
    log::error("{}: cannot replace it with this run's results: {}; they are in {}", path_.string(), error,
               file_.temporary().string());
}

std::string ResultsSink::describe() const { return "results:" + path_.string(); }

std::string ResultsSink::to_json_line(const FrameContext& ctx) { return to_json(ctx).dump(); }

nlohmann::json ResultsSink::to_json(const FrameContext& ctx) {
  using nlohmann::json;
  json j;
  j["index"] = ctx.input_index;
  j["sequence"] = ctx.camera.meta.sequence;
  j["exposure_start_ns"] = ctx.camera.meta.exposure_start_ns;
  j["dropped_before"] = ctx.dropped_before;
  if (ctx.camera.meta.source_frame_index) j["source_frame_index"] = *ctx.camera.meta.source_frame_index;
  if (ctx.camera.meta.viewpoint) j["viewpoint"] = *ctx.camera.meta.viewpoint;
  if (ctx.camera.meta.eye != Eye::Mono) j["eye"] = std::string(eye_name(ctx.camera.meta.eye));
  j["track_state"] = std::string(track_state_name(ctx.pose.state));
  if (ctx.pose.state == TrackState::Predicted) {
    j["frames_since_measured"] = ctx.pose.frames_since_measured;
    j["predicted_uncertainty_deg"] = ctx.pose.predicted_uncertainty_deg;
    j["predicted_uncertainty_mm"] = ctx.pose.predicted_uncertainty_mm;
  }
  if (ctx.pose.state == TrackState::Tracking || ctx.pose.state == TrackState::Predicted) {
    const Vec3 r = ctx.pose.T_cam_world.rotation_vector();
    const Vec3& t = ctx.pose.T_cam_world.translation();
    j["T_cam_world"] = {{"r", {r[0], r[1], r[2]}}, {"t", {t[0], t[1], t[2]}}};
    j["reprojection_rms_px"] = ctx.pose.reprojection_rms_px;
    j["ambiguous"] = ctx.pose.ambiguous;
    j["tags_used"] = ctx.pose.tags_used;
    // Where the anchor (world origin, where the virtual object stands) lands in the output image
    // (undistorted when render.lens is "undistort").
    const auto& model = ctx.output_camera_model ? ctx.output_camera_model : ctx.camera_model;
    // A stereo panorama's eye sees it where that eye's capture holds it (ods_projection.h), as
    // the render stage draws it.
    if (model) {
      Vec3 anchor = ctx.pose.T_cam_world * Vec3{0, 0, 0};
      if (ctx.camera.meta.eye != Eye::Mono)
        anchor = ods_eye_point(ctx.camera.meta.ods, ctx.camera.meta.eye,
                               mat_mul(ctx.pose.T_cam_world.rotation(), Vec3{0, 0, 1}), anchor);
      if (auto px = model->project(anchor)) j["anchor_px"] = {(*px)[0], (*px)[1]};
    }
  }
  json motion = {{"state", std::string(motion_state_name(ctx.motion.state))}};
  if (ctx.motion.valid()) {
    motion["image_motion_px"] = ctx.motion.max_image_motion_px;
    motion["exposure_ns"] = ctx.motion.timing.exposure_ns;
    motion["fallback_exposure"] = ctx.motion.fallback_exposure;
  } else if (!ctx.motion.why_none.empty()) {
    motion["why_none"] = std::string(ctx.motion.why_none);
  }
  j["motion"] = motion;
  if (ctx.light.state != LightState::None || !ctx.light.note.empty()) {
    // The light stage's estimate (absent with the config's fixed light): scene-linear units.
    json light = {{"state", std::string(light_state_name(ctx.light.state))},
                  {"source", ctx.light.source},
                  {"confidence", ctx.light.confidence}};
    if (ctx.light.frames_since_measured > 0) light["frames_since_measured"] = ctx.light.frames_since_measured;
    if (ctx.light.frames_kept > 0) light["frames_kept"] = ctx.light.frames_kept;
    if (!ctx.light.note.empty()) light["note"] = ctx.light.note;
    json lights = json::array();
    for (const DirectionalLight& l : ctx.light.lights) {
      json entry = {{"direction_world", {l.direction_world[0], l.direction_world[1], l.direction_world[2]}},
                    {"irradiance", {l.irradiance[0], l.irradiance[1], l.irradiance[2]}},
                    {"angular_diameter_deg", l.angular_diameter_rad * 180 / 3.14159265358979323846}};
      if (l.local) entry["position_world"] = {l.position_world[0], l.position_world[1], l.position_world[2]};
      lights.push_back(entry);
    }
    light["lights"] = lights;
    json sh = json::array();
    for (const Vec3& c : ctx.light.ambient_sh) sh.push_back({c[0], c[1], c[2]});
    light["ambient_sh"] = sh;
    j["light"] = light;
  }
  j["virtual_layer_drawn"] = ctx.virtual_layer_drawn;
  if (ctx.virtual_layer_drawn) j["blur"] = {{"method", ctx.blur_method}, {"samples", ctx.blur_samples}};
  if (!ctx.objects.empty()) {
    json objects = json::array();
    for (const ObjectReport& o : ctx.objects) {
      json hidden_by = json::object();
      for (const auto& [name, share] : o.hidden_by) hidden_by[name] = share;
      objects.push_back({{"index", o.index},
                         {"position_m", {o.position_m[0], o.position_m[1], o.position_m[2]}},
                         {"present", o.present},
                         {"in_view", o.in_view},
                         {"hidden", o.hidden},
                         {"hidden_by", std::move(hidden_by)}});
    }
    j["objects"] = std::move(objects);
  }
  if (ctx.physics) {
    const PhysicsReport& p = *ctx.physics;
    j["physics"] = {{"substeps", p.substeps},
                    {"restarts", p.restarts},
                    {"capped_advances", p.capped_advances},
                    {"removed", {{"below_floor", p.removed_below_floor},
                                 {"beyond_radius", p.removed_beyond_radius},
                                 {"non_finite", p.removed_non_finite}}}};
  }
  if (ctx.animation) {
    json proxies = json::array();
    for (const AnimationReport::Proxy& p : ctx.animation->proxies)
      proxies.push_back({{"name", p.name},
                         {"position_m", {p.position_m[0], p.position_m[1], p.position_m[2]}},
                         {"rotation_vector", {p.rotation_vector[0], p.rotation_vector[1], p.rotation_vector[2]}},
                         {"scale", p.scale}});
    j["animation"] = {{"time_s", ctx.animation->time_s}, {"proxies", std::move(proxies)}};
  }
  if (ctx.camera.meta.source_frame_time_ns) j["source_frame_time_s"] = 1e-9 * double(*ctx.camera.meta.source_frame_time_ns);
  json timings = json::object();
  json skips = json::object();
  for (const auto& t : ctx.timings) {
    timings[t.stage] = t.ms;
    if (!t.skipped.empty()) skips[t.stage] = t.skipped;
  }
  j["stage_ms"] = timings;
  j["skipped"] = skips;
  return j;
}

void ResultsSink::consume(const FrameContext& ctx) noexcept {
  run_started();
  std::string line;
  try {
    line = to_json_line(ctx) + "\n";
  } catch (const std::exception& e) {
    if (encode_failures_++ == 0)
      log::error("{}: cannot encode frame {}: {} (further failures are only counted)", path_.string(), ctx.input_index,
                 e.what());
    return;
  }
  // One write per line: a crash loses at most the line being written, and a failed write is cut back
  // to the previous line's end, so the file never holds a partial or merged line.
  const int error = file_.append({std::span(reinterpret_cast<const uint8_t*>(line.data()), line.size())});
  if (error) outage_.failed(ctx.input_index, std::strerror(error));
  else outage_.succeeded(ctx.input_index);
}

void ResultsSink::flush() noexcept {
  run_started();
  file_.sync();
}

}  // namespace arpipe
