// One viewpoint of a panorama source (seed 003's teleport point): its still, or its video looped
// from the moment the view arrives, and the light it gives (light.source = "panorama").
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "capture/panorama/equirect_image.h"
#include "capture/panorama/panorama_light.h"
#include "capture/panorama/panorama_video.h"
#include "core/config/panorama_config.h"
#include "core/sh/sh_basis.h"

namespace arpipe {

class PanoramaPlace {
 public:
  // Loads the still, or opens the video and decodes its first frame (the view is here until
  // leave()). carries_light: the panorama's SH too (a still's from every texel, an HDR still's
  // unclipped; a video's from each frame shown). Throws AssetError naming the file.
  // layout: how its file holds the sphere (a stereo pair: both eyes; the light is the left eye's).
  // hardware_decoding: a video tries the board's decoder first (panorama_video.h).
  PanoramaPlace(const PanoramaViewpoint& viewpoint, PanoramaLayout layout, bool carries_light,
                bool hardware_decoding = false);
  ~PanoramaPlace();
  PanoramaPlace(PanoramaPlace&&) noexcept;

  // The view arrives: a video opens and starts again from its first frame. leave() closes it, so
  // only the viewpoint in view holds a decoder.
  void arrive();
  void leave();

  // The panorama on screen t_ns after arriving (a video frame is on screen from its presentation
  // time to the next one's, the last for one frame time, then the video loops), as the eye sees it
  // (a mono layout's for any eye). Throws on a video that cannot be read back from its start.
  EquirectImage& show_at(int64_t t_ns, Eye eye = Eye::Mono);

  // The shown video frame's index (presentation order from 0); none for a still.
  std::optional<int64_t> frame_index() const;
  // Where the shown frame lies on the video's timeline: its index over the nominal rate, rounded to
  // the nanosecond (the time a pre-rendered video's animation had at that frame); 0 for a still.
  int64_t frame_time_ns() const;
  const std::optional<ShRgb9>& light_sh() const { return light_sh_; }
  const PanoramaViewpoint& viewpoint() const { return viewpoint_; }
  // Whether it holds two eyes (its layout, resolved from the file for "auto").
  bool stereo() const { return eyes_.size() > 1; }
  // Video frames skipped so far, over every visit: undecodable, or of another size than the stream's.
  uint64_t skipped_video_frames() const;
  std::string describe() const;

 private:
  // The shown frame's eyes (one for a mono layout).
  void show(PanoramaVideoFrame& frame);

  PanoramaViewpoint viewpoint_;
  PanoramaLayout layout_ = PanoramaLayout::Equirect;
  bool hardware_decoding_ = false;
  bool is_video_ = false;
  std::vector<EquirectImage> eyes_;          // the still, or the video frame shown: mono, or left and right
  std::unique_ptr<PanoramaVideo> video_;     // open while the view is here
  std::string video_description_;
  PanoramaVideoFrame shown_, upcoming_;
  bool has_upcoming_ = false;
  // Where pass `passes` of the video starts after arriving (0: the first).
  int64_t pass_start_ns(int64_t passes) const;
  // A video frame shows from its presentation time, both it and the output's time rounded to the
  // nanosecond: a frame due within this much after the output's time is already due (else an output
  // at the video's own rate would show the frame before, as the seed's viewer did by one frame).
  static constexpr int64_t kShowSlackNs = 1000;
  int64_t loop_offset_ns_ = 0;  // the start of the pass under way
  int64_t passes_ = 0;          // passes done since arriving
  int64_t pass_frames_ = 0;     // frames in one pass (known once the stream has ended)
  int64_t rate_num_ = 1, rate_den_ = 1;  // the nominal rate, frames per second as a fraction
  uint64_t skipped_before_ = 0;  // by the decoders of earlier visits
  std::unique_ptr<PanoramaLight> light_;     // a video's, for each frame shown
  std::optional<ShRgb9> light_sh_;
};

}  // namespace arpipe
