#include "capture/panorama/panorama_source.h"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <optional>
#include <vector>

#include "capture/pacing_clock.h"
#include "capture/panorama/head_pose_track.h"
#include "capture/panorama/panorama_place.h"
#include "capture/panorama/panorama_view.h"
#include "core/environment/hdr_environment.h"
#include "core/log.h"
#include "core/pipeline/frame_times.h"
#include "core/scene/asset_error.h"

namespace arpipe {

SE3 panorama_view_pose(const PanoramaViewpoint& viewpoint, const Mat3& R_pano_cam) {
  const Mat3 R_world_cam = mat_mul(default_world_from_probe(viewpoint.yaw_rad), R_pano_cam);
  const Mat3 R_cam_world = transpose(R_world_cam);
  return SE3(R_cam_world, -1.0 * mat_mul(R_cam_world, viewpoint.position_m));
}

Mat3 panorama_view_rotation_at(const PanoramaConfig& config, double t_s) {
  return panorama_view_rotation(config.view.yaw_rad + config.view.yaw_rad_per_s * t_s, config.view.pitch_rad);
}

PanoramaStop panorama_stop_at(const PanoramaConfig& config, int64_t t_ns) {
  const int64_t count = int64_t(config.viewpoint_count());
  if (count <= 1 || config.view.dwell_s <= 0) return {0, 0};
  const int64_t dwell_ns = std::max<int64_t>(1, std::llround(config.view.dwell_s * 1e9));
  const int64_t visits = t_ns / dwell_ns;  // t_ns >= 0
  return {size_t(visits % count), visits * dwell_ns};
}

struct PanoramaSource::Impl {
  SourceConfig config;
  std::vector<PanoramaPlace> places;  // per viewpoint
  size_t here = 0;                    // the viewpoint in view
  std::unique_ptr<PanoramaView> view;
  std::optional<HeadPoseTrack> track;  // source.panorama.view.track, else the sweep
  int64_t interval_ns = 0;
  uint64_t next_index = 0;
  PacingClock clock;
  std::atomic<uint64_t> skipped_video_frames{0}, failed_frames{0};  // for health(), from any thread

  // The view's turn at time t_s: the track's (turned right by the view's yaw) at t_s, or the
  // sweep's, which starts again at each viewpoint (since_arrival_s).
  Mat3 rotation_at(double t_s, double since_arrival_s) const;
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

Mat3 PanoramaSource::Impl::rotation_at(double t_s, double since_arrival_s) const {
  if (!track) return panorama_view_rotation_at(config.panorama, since_arrival_s);
  // The yaw as a turn of the panorama's frame about its up: the yawed view's axes times the
  // unturned view's (diag(1, -1, -1), its own inverse).
  Mat3 turn = panorama_view_rotation(config.panorama.view.yaw_rad, 0);
  for (auto& row : turn) row[1] = -row[1], row[2] = -row[2];
  return mat_mul(turn, track->rotation_at(t_s));
}

PanoramaSource::PanoramaSource(const SourceConfig& config, bool carries_light) : impl_(std::make_unique<Impl>()) {
  impl_->config = config;
  const PanoramaConfig& panorama = config.panorama;
  // Each place opens its video to check it; only the first, in view, keeps its decoder.
  for (size_t k = 0; k < panorama.viewpoint_count(); ++k) {
    impl_->places.emplace_back(panorama.viewpoint(k), panorama.layout, carries_light, panorama.hardware_decoding);
    if (k > 0) impl_->places.back().leave();
  }
  // Every viewpoint mono, or every one stereo: the frames of a time step are one or two throughout.
  for (const PanoramaPlace& place : impl_->places)
    if (place.stereo() != impl_->places.front().stereo())
      throw AssetError(fmt::format("panorama \"{}\" is {} but \"{}\" is {}: the viewpoints must all be mono or all stereo",
                                   place.viewpoint().file.string(), place.stereo() ? "stereo" : "mono",
                                   impl_->places.front().viewpoint().file.string(),
                                   impl_->places.front().stereo() ? "stereo" : "mono"));
  if (!panorama.view.track.empty()) impl_->track = HeadPoseTrack::load(panorama.view.track);
  impl_->view = std::make_unique<PanoramaView>(view_camera(panorama.view));
  impl_->interval_ns = std::llround(1e9 / panorama.view.fps);
}

PanoramaSource::~PanoramaSource() = default;

std::string PanoramaSource::describe() const {
  std::string places;
  for (const PanoramaPlace& place : impl_->places) places += (places.empty() ? "" : ", ") + place.describe();
  return fmt::format("panorama {} seen {} x {}", places, impl_->view->camera()->width(), impl_->view->camera()->height());
}

std::shared_ptr<const CameraModel> PanoramaSource::camera_model() const { return impl_->view->camera(); }

std::optional<int64_t> PanoramaSource::frame_interval_ns() const { return impl_->interval_ns; }

void PanoramaSource::interrupt() { impl_->clock.interrupt(); }

std::string PanoramaSource::health() const {
  const uint64_t skipped = impl_->skipped_video_frames, failed = impl_->failed_frames;
  if (skipped == 0 && failed == 0) return {};
  return fmt::format("video frames skipped {} (undecodable or of another size), frames failed {}", skipped, failed);
}

SourceStatus PanoramaSource::next(Frame& frame) {
  Impl& s = *impl_;
  const PanoramaConfig& panorama = s.config.panorama;
  // A stereo layout gives each time step twice: its left eye's frame, then its right eye's.
  const uint64_t eyes = s.places.front().stereo() ? 2 : 1;
  if (panorama.view.frames > 0 && s.next_index >= uint64_t(panorama.view.frames) * eyes) return SourceStatus::EndOfStream;
  const uint64_t index = s.next_index, step = index / eyes;
  const Eye eye = eyes == 1 ? Eye::Mono : index % 2 == 0 ? Eye::Left : Eye::Right;
  int64_t start_ns = 0;
  // Output frame k is at k / fps exactly, rounded to the nanosecond (k times a rounded interval
  // would fall behind a video at the same rate by a third of a nanosecond a frame at 30 frames/s);
  // nothing past 285 years.
  if (!(double(step) / panorama.view.fps < 9e9)) return SourceStatus::EndOfStream;
  start_ns = frame_offset_ns(panorama.view.fps, step);
  try {
    if (s.config.pacing == ReplayPacing::Timestamps && !s.clock.wait(start_ns)) return SourceStatus::Retry;
    const double t_s = double(step) / panorama.view.fps;
    // Teleport: the next viewpoint after dwell_s (its video from the start, its sweep again).
    const PanoramaStop stop = panorama_stop_at(panorama, start_ns);
    if (stop.viewpoint != s.here) {
      s.places[s.here].leave();
      s.here = stop.viewpoint;
      s.places[s.here].arrive();
    }
    PanoramaPlace& place = s.places[s.here];
    EquirectImage& image = place.show_at(start_ns - stop.arrived_ns, eye);
    const CameraModel& camera = *s.view->camera();
    frame = Frame::allocate(PixelFormat::RGB24, camera.width(), camera.height());
    const Mat3 R_pano_cam = s.rotation_at(t_s, 1e-9 * double(start_ns - stop.arrived_ns));
    s.view->render(image, R_pano_cam, frame.data.data(), frame.bytes_per_line);
    frame.meta = FrameMetadata{};
    frame.meta.sequence = index;
    frame.meta.exposure_start_ns = start_ns + s.config.timestamp_offset_ns;
    frame.meta.raw_timestamp_ns = start_ns;
    frame.meta.frame_duration_ns = s.interval_ns;
    frame.meta.timestamp_offset_ns = s.config.timestamp_offset_ns;
    frame.meta.known_T_cam_world = panorama_view_pose(place.viewpoint(), R_pano_cam);
    frame.meta.source_frame_index = place.frame_index();
    frame.meta.source_frame_time_ns = place.frame_time_ns();
    frame.meta.viewpoint = int(s.here);
    frame.meta.eye = eye;
    frame.meta.ods = panorama.ods_rig();
    frame.meta.environment_sh = place.light_sh();
    uint64_t skipped = 0;
    for (const PanoramaPlace& p : s.places) skipped += p.skipped_video_frames();
    s.skipped_video_frames = skipped;
    s.next_index = index + 1;
    return SourceStatus::Frame;
  } catch (const std::exception& e) {  // per-frame code never throws (docs/DESIGN.md "Errors")
    log::error("panorama {}: frame {}: {}", panorama.file.string(), index, e.what());
    ++s.failed_frames;
    s.next_index = index + 1;
    return SourceStatus::Retry;
  }
}

}  // namespace arpipe
