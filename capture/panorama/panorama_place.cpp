#include "capture/panorama/panorama_place.h"

#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>

#include "capture/panorama/panorama_file_kind.h"
#include "capture/panorama/stereo_eye_pixels.h"
#include "core/environment/hdr_environment.h"
#include "core/image/hdr_file.h"
#include "core/pipeline/frame_times.h"
#include "core/scene/asset_error.h"

namespace arpipe {
namespace {

// A video frame's light: each block's mean from 4 x 4 of its texels (a still's from every texel).
constexpr int kVideoLightTaps = 4;

// A stereo pair's left eye (the whole image for a mono layout), whose shape the loader checked
// against the layout ("auto": told by the shape).
HdrImage left_eye(HdrImage whole, PanoramaLayout layout) {
  if (layout == PanoramaLayout::Auto) layout = layout_of_shape(whole.width, whole.height);
  if (layout == PanoramaLayout::Equirect) return whole;
  const bool top_bottom = layout == PanoramaLayout::EquirectTopBottom;
  HdrImage eye;
  eye.width = top_bottom ? whole.width : whole.width / 2;
  eye.height = top_bottom ? whole.height / 2 : whole.height;
  eye.rgb = stereo_eye_pixels(whole.rgb, whole.width, whole.height, top_bottom, 0);
  return eye;
}

}  // namespace

PanoramaPlace::PanoramaPlace(const PanoramaViewpoint& viewpoint, PanoramaLayout layout, bool carries_light,
                             bool hardware_decoding)
    : viewpoint_(viewpoint), layout_(layout), hardware_decoding_(hardware_decoding), is_video_(panorama_file_kind(viewpoint.file) == PanoramaFileKind::Video) {
  const Mat3 R_world_pano = default_world_from_probe(viewpoint.yaw_rad);
  if (is_video_) {
    arrive();  // checks that a frame decodes
    layout_ = video_->layout();  // Auto resolved: reopened so on each arrival
    video_description_ = video_->describe();
    if (carries_light) {
      light_ = std::make_unique<PanoramaLight>(eyes_.front().width(), eyes_.front().height(), R_world_pano);
      light_sh_ = light_->project(eyes_.front(), kVideoLightTaps);
    }
    return;
  }
  eyes_ = EquirectImage::load_eyes(viewpoint.file, viewpoint.hdr_scale, layout);
  if (carries_light) {
    // Every texel, once; an HDR file's unclipped radiance rather than the displayed picture's.
    const EquirectImage& left = eyes_.front();
    const PanoramaLight light(left.width(), left.height(), R_world_pano);
    light_sh_ = panorama_file_kind(viewpoint.file) == PanoramaFileKind::Hdr
                    ? light.project(left_eye(read_hdr_image(viewpoint.file), layout), viewpoint.hdr_scale)
                    : light.project(left);
  }
}

PanoramaPlace::~PanoramaPlace() = default;
PanoramaPlace::PanoramaPlace(PanoramaPlace&&) noexcept = default;

void PanoramaPlace::arrive() {
  if (!is_video_) return;
  video_ = std::make_unique<PanoramaVideo>(viewpoint_.file, layout_, hardware_decoding_);
  rate_num_ = video_->rate_num();
  rate_den_ = video_->rate_den();
  loop_offset_ns_ = 0;
  passes_ = 0;
  if (!video_->next(shown_)) throw AssetError(fmt::format("panorama video \"{}\": no frame decodes", viewpoint_.file.string()));
  has_upcoming_ = video_->next(upcoming_);
  show(shown_);
}

void PanoramaPlace::show(PanoramaVideoFrame& frame) {
  eyes_ = EquirectImage::split(std::move(frame.rgb), frame.width, frame.height, layout_, viewpoint_.file.string());
  // EquirectImage took the pixels: keep the size for the next swap.
  frame.rgb.clear();
  if (light_) light_sh_ = light_->project(eyes_.front(), kVideoLightTaps);
}

void PanoramaPlace::leave() {
  if (!video_) return;
  skipped_before_ += video_->decode_errors();
  video_.reset();
}

uint64_t PanoramaPlace::skipped_video_frames() const { return skipped_before_ + (video_ ? video_->decode_errors() : 0); }

EquirectImage& PanoramaPlace::show_at(int64_t t_ns, Eye eye) {
  const size_t which = eye == Eye::Right && eyes_.size() > 1 ? 1 : 0;
  if (!is_video_) return eyes_[which];
  if (!video_) arrive();
  const auto fetch = [&] { has_upcoming_ = video_->next(upcoming_); };
  bool changed = false;
  for (;;) {
    while (has_upcoming_ && upcoming_.time_ns <= t_ns - loop_offset_ns_ + kShowSlackNs) {
      std::swap(shown_, upcoming_);
      changed = true;
      fetch();
    }
    if (has_upcoming_) break;
    // The stream ended: the last frame lasts one frame time, then the video starts again. A pass is
    // its frames at the nominal rate, each pass's start exact however many there were (no drift).
    pass_frames_ = shown_.index + 1;
    const int64_t next_pass_ns = pass_start_ns(passes_ + 1);
    if (t_ns + kShowSlackNs < next_pass_ns) break;
    ++passes_;
    loop_offset_ns_ = next_pass_ns;
    video_->seek(0);
    fetch();
    if (!has_upcoming_) throw std::runtime_error("no frame after seeking to the start");
  }
  if (changed) show(shown_);
  return eyes_[which];
}

std::optional<int64_t> PanoramaPlace::frame_index() const {
  if (!is_video_) return std::nullopt;
  return shown_.index;
}

int64_t PanoramaPlace::frame_time_ns() const { return is_video_ ? frames_to_ns(shown_.index, rate_num_, rate_den_) : 0; }

int64_t PanoramaPlace::pass_start_ns(int64_t passes) const {
  return frames_to_ns(passes * pass_frames_, rate_num_, rate_den_);
}

std::string PanoramaPlace::describe() const {
  return fmt::format("{} ({})", viewpoint_.file.string(),
                     is_video_ ? video_description_
                               : fmt::format("{} x {}{}", eyes_.front().width(), eyes_.front().height(),
                                             eyes_.size() > 1 ? " a stereo eye" : ""));
}

}  // namespace arpipe
