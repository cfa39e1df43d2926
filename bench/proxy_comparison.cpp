// Phantom proxies against the simulator's coverage (see proxy_comparison.h).
#include "bench/proxy_comparison.h"

#include <GLES3/gl3.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "capture/recording/recording_reader.h"
#include "core/motion/shutter_motion.h"
#include "core/pipeline/frame_context.h"
#include "render/gl/gl_error.h"
#include "render/gl/gl_objects.h"
#include "render/gl_stages.h"

namespace arpipe::bench {

double median_of(std::vector<double> values) {
  if (values.empty()) return 0;
  std::nth_element(values.begin(), values.begin() + long(values.size() / 2), values.end());
  return values[values.size() / 2];
}

namespace {

// The frame's camera motion from the ground truth, as the motion stage would give it exactly.
ShutterMotion motion_from_truth(const FrameMetadata& meta, const GroundTruthFrame& truth, int rows) {
  ShutterMotion motion;
  motion.state = MotionState::Interpolated;
  motion.timing = shutter_timing(meta, rows, 10'000'000);
  motion.pose_time_ns = motion.timing.mid_ns();
  motion.T_cam_world_start = truth.T_cam_world_start;
  motion.T_cam_world_mid = truth.T_cam_world_mid;
  motion.T_cam_world_end = truth.T_cam_world_end;
  return motion;
}

// The longest image path of the first object's box corners from the exposure's start to its end.
double first_object_motion_px(const CameraModel& camera, const ShutterMotion& motion, const Config& config) {
  if (config.render.objects.empty()) return 0;
  const SceneObject& object = config.render.objects[0];
  const SE3 T_world_object = SE3::from_rt({0, 0, object.yaw_rad}, object.position_m);
  const double h = 0.03 * object.scale;  // a builtin's 6 cm box
  double most = 0;
  for (int i = 0; i < 8; ++i) {
    const Vec3 world = T_world_object * Vec3{(i & 1) ? h : -h, (i & 2) ? h : -h, (i & 4) ? 2 * h : 0.0};
    const std::optional<Vec2> a = camera.project(motion.T_cam_world_start * world);
    const std::optional<Vec2> b = camera.project(motion.T_cam_world_end * world);
    if (a && b) most = std::max(most, std::hypot((*a)[0] - (*b)[0], (*a)[1] - (*b)[1]));
  }
  return most;
}

}  // namespace

std::vector<float> layer_alpha(const VirtualLayerTexture& layer) {
  GlFramebuffer framebuffer = GlFramebuffer::create();
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer.get());
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, layer.texture, 0);
  std::vector<float> rgba(size_t(layer.width) * layer.height * 4);
  glReadPixels(0, 0, layer.width, layer.height, GL_RGBA, GL_FLOAT, rgba.data());
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  check_gl("reading the virtual layer back");
  std::vector<float> alpha(size_t(layer.width) * layer.height, 0.0f);
  for (int y = layer.y; y < layer.y + layer.rect_height; ++y)
    for (int x = layer.x; x < layer.x + layer.rect_width; ++x) {
      const size_t i = size_t(y) * layer.width + x;
      alpha[i] = rgba[4 * i + 3];
    }
  return alpha;
}

namespace {

double timing_ms(const FrameContext& ctx, std::string_view stage) {
  for (const StageTiming& t : ctx.timings)
    if (t.stage == stage) return t.ms;
  return 0;
}

}  // namespace

EdgeError occlusion_edge_error(const std::vector<float>& drawn, const sim::CoverageImage& truth) {
  const int w = truth.width, h = truth.height;
  if (drawn.size() != truth.coverage.size()) throw std::invalid_argument("occlusion_edge_error: sizes differ");
  double differing = 0, length = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t i = size_t(y) * w + x;
      differing += (drawn[i] >= 0.5f) != (truth.coverage[i] >= 0.5f);
      const double dx = x + 1 < w ? truth.coverage[i + 1] - truth.coverage[i] : 0.0;
      const double dy = y + 1 < h ? truth.coverage[i + size_t(w)] - truth.coverage[i] : 0.0;
      length += std::hypot(dx, dy);
    }
  return {length > 0 ? differing / length : 0.0, length};
}

ProxyCaptureRun run_proxy_capture(const std::filesystem::path& capture, const Config& config, int repeats) {
  RecordingReader reader(capture);
  if (reader.ground_truth().size() < reader.frame_count())
    throw std::runtime_error(fmt::format("{}: no ground truth for every frame", capture.string()));
  const auto camera = std::make_shared<const CameraModel>(reader.camera_model());
  std::vector<std::unique_ptr<Stage>> stages = make_gl_stages();
  for (auto& stage : stages) stage->configure(config);
  ProxyCaptureRun run;
  std::vector<double> render_ms, occlusion_ms;
  for (int repeat = 0; repeat < std::max(1, repeats); ++repeat)
    for (size_t i = 0; i < reader.frame_count(); ++i) {
      FrameContext ctx;
      reader.read(i, ctx.camera);
      ctx.camera_model = camera;
      const GroundTruthFrame& truth = reader.ground_truth()[i];
      ctx.pose.state = TrackState::Tracking;
      ctx.pose.T_cam_world = truth.T_cam_world_mid;
      ctx.motion = motion_from_truth(reader.metadata(i), truth, camera->height());
      const double motion_px = first_object_motion_px(*camera, ctx.motion, config);
      ctx.motion.max_image_motion_px = motion_px;
      for (auto& stage : stages) stage->process(ctx);
      if (!ctx.virtual_layer_drawn) throw std::runtime_error(fmt::format("{}: frame {} was not drawn", capture.string(), i));
      render_ms.push_back(timing_ms(ctx, "render"));
      occlusion_ms.push_back(timing_ms(ctx, "occlusion"));
      if (repeat > 0) continue;
      ProxyFrame frame;
      frame.motion_px = motion_px;
      frame.edge = occlusion_edge_error(layer_alpha(ctx.virtual_layer), sim::read_coverage_frame(capture, i));
      frame.blur_method = ctx.blur_method;
      frame.blur_samples = ctx.blur_samples;
      frame.hidden = ctx.objects.empty() ? -1.0 : ctx.objects[0].hidden;
      const bool still = motion_px < 1.0;
      double& worst = still ? run.worst_still_px : run.worst_blurred_px;
      double& mean = still ? run.mean_still_px : run.mean_blurred_px;
      worst = std::max(worst, frame.edge.displacement_px);
      mean += frame.edge.displacement_px;
      ++(still ? run.still_frames : run.blurred_frames);
      run.frames.push_back(frame);
    }
  if (run.still_frames) run.mean_still_px /= run.still_frames;
  if (run.blurred_frames) run.mean_blurred_px /= run.blurred_frames;
  run.render_ms = median_of(render_ms);
  run.occlusion_ms = median_of(occlusion_ms);
  return run;
}

}  // namespace arpipe::bench
