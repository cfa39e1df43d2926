#include "capture/panorama/panorama_place.h"

#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>

#include "capture/panorama/panorama_file_kind.h"
#include "core/environment/hdr_environment.h"
#include "core/image/hdr_file.h"
#include "core/scene/asset_error.h"

namespace arpipe {
namespace {

// A video frame's light: each block's mean from 4 x 4 of its texels (a still's from every texel).
constexpr int kVideoLightTaps = 4;

}  // namespace

PanoramaPlace::PanoramaPlace(const PanoramaViewpoint& viewpoint, bool carries_light)
    : viewpoint_(viewpoint), is_video_(panorama_file_kind(viewpoint.file) == PanoramaFileKind::Video) {
  const Mat3 R_world_pano = default_world_from_probe(viewpoint.yaw_rad);
  if (is_video_) {
    arrive();  // checks that a frame decodes
    video_description_ = video_->describe();
    if (carries_light) {
      light_ = std::make_unique<PanoramaLight>(panorama_->width(), panorama_->height(), R_world_pano);
      light_sh_ = light_->project(*panorama_, kVideoLightTaps);
    }
    return;
  }
  panorama_ = std::make_unique<EquirectImage>(EquirectImage::load(viewpoint.file, viewpoint.hdr_scale));
  if (carries_light) {
    // Every texel, once; an HDR file's unclipped radiance rather than the displayed picture's.
    const PanoramaLight light(panorama_->width(), panorama_->height(), R_world_pano);
    light_sh_ = panorama_file_kind(viewpoint.file) == PanoramaFileKind::Hdr
                    ? light.project(read_hdr_image(viewpoint.file), viewpoint.hdr_scale)
                    : light.project(*panorama_);
  }
}

PanoramaPlace::~PanoramaPlace() = default;
PanoramaPlace::PanoramaPlace(PanoramaPlace&&) noexcept = default;

void PanoramaPlace::arrive() {
  if (!is_video_) return;
  video_ = std::make_unique<PanoramaVideo>(viewpoint_.file);
  video_frame_ns_ = std::max<int64_t>(1, (1'000'000'000 * video_->rate_den() + video_->rate_num() / 2) / video_->rate_num());
  loop_offset_ns_ = 0;
  if (!video_->next(shown_)) throw AssetError(fmt::format("panorama video \"{}\": no frame decodes", viewpoint_.file.string()));
  has_upcoming_ = video_->next(upcoming_);
  panorama_ = std::make_unique<EquirectImage>(std::move(shown_.rgb), shown_.width, shown_.height, viewpoint_.file.string());
  shown_.rgb.clear();
  if (light_) light_sh_ = light_->project(*panorama_, kVideoLightTaps);
}

void PanoramaPlace::leave() {
  if (!video_) return;
  skipped_before_ += video_->decode_errors();
  video_.reset();
}

uint64_t PanoramaPlace::skipped_video_frames() const { return skipped_before_ + (video_ ? video_->decode_errors() : 0); }

EquirectImage& PanoramaPlace::show_at(int64_t t_ns) {
  if (!is_video_) return *panorama_;
  if (!video_) arrive();
  const auto fetch = [&] { has_upcoming_ = video_->next(upcoming_); };
  bool changed = false;
  for (;;) {
    while (has_upcoming_ && upcoming_.time_ns <= t_ns - loop_offset_ns_) {
      std::swap(shown_, upcoming_);
      changed = true;
      fetch();
    }
    if (has_upcoming_) break;
    // The stream ended: the last frame lasts one frame time, then the video starts again.
    const int64_t period = shown_.time_ns + video_frame_ns_;
    if (t_ns - loop_offset_ns_ < period) break;
    loop_offset_ns_ += period;
    video_->seek(0);
    fetch();
    if (!has_upcoming_) throw std::runtime_error("no frame after seeking to the start");
  }
  if (changed) {
    panorama_ = std::make_unique<EquirectImage>(std::move(shown_.rgb), shown_.width, shown_.height, viewpoint_.file.string());
    if (light_) light_sh_ = light_->project(*panorama_, kVideoLightTaps);
  }
  // EquirectImage took the pixels: keep the size for the next swap.
  shown_.rgb.clear();
  return *panorama_;
}

std::optional<int64_t> PanoramaPlace::frame_index() const {
  if (!is_video_) return std::nullopt;
  return shown_.index;
}

std::string PanoramaPlace::describe() const {
  return fmt::format("{} ({})", viewpoint_.file.string(),
                     is_video_ ? video_description_ : fmt::format("{} x {}", panorama_->width(), panorama_->height()));
}

}  // namespace arpipe
