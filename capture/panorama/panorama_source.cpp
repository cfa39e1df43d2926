#include "capture/panorama/panorama_source.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>

#include "capture/pacing_clock.h"
#include "capture/panorama/equirect_image.h"
#include "capture/panorama/head_pose_track.h"
#include "capture/panorama/panorama_light.h"
#include "capture/panorama/panorama_file_kind.h"
#include "capture/panorama/panorama_video.h"
#include "capture/panorama/panorama_view.h"
#include "core/environment/hdr_environment.h"
#include "core/image/hdr_file.h"
#include "core/log.h"
#include "core/scene/asset_error.h"

namespace arpipe {

SE3 panorama_view_pose(const PanoramaConfig& config, const Mat3& R_pano_cam) {
  const Mat3 R_world_cam = mat_mul(default_world_from_probe(config.yaw_rad), R_pano_cam);
  const Mat3 R_cam_world = transpose(R_world_cam);
  return SE3(R_cam_world, -1.0 * mat_mul(R_cam_world, config.position_m));
}

Mat3 panorama_view_rotation_at(const PanoramaConfig& config, double t_s) {
  return panorama_view_rotation(config.view.yaw_rad + config.view.yaw_rad_per_s * t_s, config.view.pitch_rad);
}

// A video frame's light: each block's mean from 4 x 4 of its texels (a still's from every texel).
constexpr int kVideoLightTaps = 4;

struct PanoramaSource::Impl {
  SourceConfig config;
  std::unique_ptr<EquirectImage> panorama;  // the still, or the video frame shown
  // A video: the frame shown (its index and time), the one after it, and the loop's passes.
  std::unique_ptr<PanoramaVideo> video;
  PanoramaVideoFrame shown, upcoming;
  bool has_upcoming = false;
  int64_t loop_offset_ns = 0;  // the durations of the passes done
  int64_t video_frame_ns = 0;  // one frame at the video's nominal rate

  // Makes `shown` the video frame on screen at output time t_ns, looping (a frame is on screen from
  // its presentation time to the next one's; the last one for one frame time).
  void show_video_at(int64_t t_ns);
  // The view's turn at time t_s: the track's (turned right by the view's yaw) or the sweep's.
  Mat3 rotation_at(double t_s) const;
  std::unique_ptr<PanoramaView> view;
  std::optional<HeadPoseTrack> track;  // source.panorama.view.track, else the sweep
  std::unique_ptr<PanoramaLight> light;  // carries_light: the panorama's SH, for each frame shown
  std::optional<ShRgb9> light_sh;
  int64_t interval_ns = 0;
  uint64_t next_index = 0;
  PacingClock clock;
};

namespace {

std::shared_ptr<const CameraModel> view_camera(const PanoramaViewConfig& view) {
  if (!view.camera_model.empty()) return std::make_shared<const CameraModel>(CameraModel::load(view.camera_model));
  // A pinhole of the given horizontal field of view, square pixels, centred.
  const double fx = 0.5 * view.width / std::tan(0.5 * view.hfov_rad);
  return std::make_shared<const CameraModel>(
      CameraModel::pinhole(fx, fx, 0.5 * (view.width - 1), 0.5 * (view.height - 1), view.width, view.height));
}

}  // namespace

void PanoramaSource::Impl::show_video_at(int64_t t_ns) {
  const auto fetch = [&] { has_upcoming = video->next(upcoming); };
  bool changed = false;
  for (;;) {
    while (has_upcoming && upcoming.time_ns <= t_ns - loop_offset_ns) {
      std::swap(shown, upcoming);
      changed = true;
      fetch();
    }
    if (has_upcoming) break;
    // The stream ended: the last frame lasts one frame time, then the video starts again.
    const int64_t period = shown.time_ns + video_frame_ns;
    if (t_ns - loop_offset_ns < period) break;
    loop_offset_ns += period;
    video->seek(0);
    fetch();
    if (!has_upcoming) throw std::runtime_error("no frame after seeking to the start");
  }
  if (changed || !panorama) {
    panorama = std::make_unique<EquirectImage>(std::move(shown.rgb), shown.width, shown.height, config.panorama.file.string());
    if (light) light_sh = light->project(*panorama, kVideoLightTaps);
  }
  // EquirectImage took the pixels: keep the size for the next swap.
  shown.rgb.clear();
}

Mat3 PanoramaSource::Impl::rotation_at(double t_s) const {
  if (!track) return panorama_view_rotation_at(config.panorama, t_s);
  // The yaw as a turn of the panorama's frame about its up: the yawed view's axes times the
  // unturned view's (diag(1, -1, -1), its own inverse).
  Mat3 turn = panorama_view_rotation(config.panorama.view.yaw_rad, 0);
  for (auto& row : turn) row[1] = -row[1], row[2] = -row[2];
  return mat_mul(turn, track->rotation_at(t_s));
}

PanoramaSource::PanoramaSource(const SourceConfig& config, bool carries_light) : impl_(std::make_unique<Impl>()) {
  impl_->config = config;
  const PanoramaConfig& panorama = config.panorama;
  if (panorama_file_kind(panorama.file) == PanoramaFileKind::Video) {
    Impl& s = *impl_;
    s.video = std::make_unique<PanoramaVideo>(panorama.file);
    s.video_frame_ns = std::max<int64_t>(1, (1'000'000'000 * s.video->rate_den() + s.video->rate_num() / 2) / s.video->rate_num());
    if (!s.video->next(s.shown))
      throw AssetError(fmt::format("panorama video \"{}\": no frame decodes", panorama.file.string()));
    s.has_upcoming = s.video->next(s.upcoming);
    s.panorama = std::make_unique<EquirectImage>(std::move(s.shown.rgb), s.shown.width, s.shown.height, panorama.file.string());
    s.shown.rgb.clear();
    if (carries_light) {
      s.light = std::make_unique<PanoramaLight>(s.panorama->width(), s.panorama->height(), default_world_from_probe(panorama.yaw_rad));
      s.light_sh = s.light->project(*s.panorama, kVideoLightTaps);
    }
  } else {
    impl_->panorama = std::make_unique<EquirectImage>(EquirectImage::load(panorama.file, panorama.hdr_scale));
    if (carries_light) {
      // Every texel, once; an HDR file's unclipped radiance rather than the displayed picture's.
      const PanoramaLight light(impl_->panorama->width(), impl_->panorama->height(), default_world_from_probe(panorama.yaw_rad));
      impl_->light_sh = panorama_file_kind(panorama.file) == PanoramaFileKind::Hdr
                            ? light.project(read_hdr_image(panorama.file), panorama.hdr_scale)
                            : light.project(*impl_->panorama);
    }
  }
  if (!panorama.view.track.empty()) impl_->track = HeadPoseTrack::load(panorama.view.track);
  impl_->view = std::make_unique<PanoramaView>(view_camera(panorama.view));
  impl_->interval_ns = std::llround(1e9 / panorama.view.fps);
}

PanoramaSource::~PanoramaSource() = default;

std::string PanoramaSource::describe() const {
  return fmt::format("panorama {} ({}) seen {} x {}", impl_->config.panorama.file.string(),
                     impl_->video ? impl_->video->describe() : fmt::format("{} x {}", impl_->panorama->width(), impl_->panorama->height()),
                     impl_->view->camera()->width(), impl_->view->camera()->height());
}

std::shared_ptr<const CameraModel> PanoramaSource::camera_model() const { return impl_->view->camera(); }

std::optional<int64_t> PanoramaSource::frame_interval_ns() const { return impl_->interval_ns; }

void PanoramaSource::interrupt() { impl_->clock.interrupt(); }

SourceStatus PanoramaSource::next(Frame& frame) {
  Impl& s = *impl_;
  const PanoramaConfig& panorama = s.config.panorama;
  if (panorama.view.frames > 0 && s.next_index >= uint64_t(panorama.view.frames)) return SourceStatus::EndOfStream;
  const uint64_t index = s.next_index;
  int64_t start_ns = 0;
  if (__builtin_mul_overflow(int64_t(index), s.interval_ns, &start_ns)) return SourceStatus::EndOfStream;
  try {
    if (s.config.pacing == ReplayPacing::Timestamps && !s.clock.wait(start_ns)) return SourceStatus::Retry;
    const double t_s = double(index) / panorama.view.fps;
    if (s.video) s.show_video_at(start_ns);
    const CameraModel& camera = *s.view->camera();
    frame = Frame::allocate(PixelFormat::RGB24, camera.width(), camera.height());
    const Mat3 R_pano_cam = s.rotation_at(t_s);
    s.view->render(*s.panorama, R_pano_cam, frame.data.data(), frame.bytes_per_line);
    frame.meta = FrameMetadata{};
    frame.meta.sequence = index;
    frame.meta.exposure_start_ns = start_ns + s.config.timestamp_offset_ns;
    frame.meta.raw_timestamp_ns = start_ns;
    frame.meta.frame_duration_ns = s.interval_ns;
    frame.meta.timestamp_offset_ns = s.config.timestamp_offset_ns;
    frame.meta.known_T_cam_world = panorama_view_pose(panorama, R_pano_cam);
    if (s.video) frame.meta.source_frame_index = s.shown.index;
    frame.meta.environment_sh = s.light_sh;
    s.next_index = index + 1;
    return SourceStatus::Frame;
  } catch (const std::exception& e) {  // per-frame code never throws (docs/DESIGN.md "Errors")
    log::error("panorama {}: frame {}: {}", panorama.file.string(), index, e.what());
    s.next_index = index + 1;
    return SourceStatus::Retry;
  }
}

}  // namespace arpipe
