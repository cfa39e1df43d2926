// A stereo panorama's two eyes as one output frame.
#include "core/pipeline/stereo_packer.h"

#include <algorithm>
#include <memory>


namespace arpipe {

Frame pack_stereo_pair(const Frame& left, const Frame& right, StereoOutput packing) {
  if (left.format != PixelFormat::RGB24 || right.format != left.format || right.width != left.width ||
      right.height != left.height || left.empty() || right.empty())
    return {};
  const bool top_bottom = packing == StereoOutput::TopBottom;
  Frame pair = Frame::allocate(left.format, top_bottom ? left.width : 2 * left.width,
                               top_bottom ? 2 * left.height : left.height);
  pair.meta = left.meta;
  const size_t row = size_t(left.width) * 3;
  for (int y = 0; y < left.height; ++y) {
    const uint8_t* l = left.data.data() + size_t(y) * left.bytes_per_line;
    const uint8_t* r = right.data.data() + size_t(y) * right.bytes_per_line;
    uint8_t* to_left = pair.data.data() + size_t(y) * pair.bytes_per_line;
    uint8_t* to_right = top_bottom ? pair.data.data() + size_t(y + left.height) * pair.bytes_per_line : to_left + row;
    std::copy_n(l, row, to_left);
    std::copy_n(r, row, to_right);
  }
  return pair;
}

std::shared_ptr<const CameraModel> StereoPacker::lens_over_pair(const std::shared_ptr<const CameraModel>& eye,
                                                                const Frame& pair) {
  if (!eye || pair.empty()) return eye;
  // The same eye lens and pair size every frame: made once.
  for (const PairLens& known : lenses_)
    if (known.eye == eye && known.over->width() == pair.width && known.over->height() == pair.height) return known.over;
  PairLens made{eye, std::make_shared<const CameraModel>(eye->lensmodel(), eye->intrinsics(), pair.width, pair.height)};
  if (lenses_.size() >= 4) lenses_.erase(lenses_.begin());
  lenses_.push_back(made);
  return made.over;
}

std::optional<FrameContext> StereoPacker::add(FrameContext ctx) {
  const Eye eye = ctx.camera.meta.eye;
  if (eye == Eye::Mono || eye == Eye::Pair) return ctx;
  if (eye == Eye::Left) {
    if (left_) ++unpaired_;  // the right eye of the one held never came
    left_ = std::move(ctx);
    return std::nullopt;
  }
  // The right eye: of the held left eye's time step, or without one.
  if (!left_ || left_->camera.meta.exposure_start_ns != ctx.camera.meta.exposure_start_ns) {
    if (left_) ++unpaired_;
    left_.reset();
    ++unpaired_;
    return std::nullopt;
  }
  FrameContext pair = std::move(*left_);
  left_.reset();
  pair.output = pack_stereo_pair(pair.output, ctx.output, packing_);
  pair.output.meta.eye = Eye::Pair;
  pair.output_camera_model = lens_over_pair(pair.output_camera_model ? pair.output_camera_model : pair.camera_model, pair.output);
  if (Frame camera = pack_stereo_pair(pair.camera, ctx.camera, packing_); !camera.empty()) {
    pair.camera = std::move(camera);
    pair.camera_model = lens_over_pair(pair.camera_model, pair.camera);
  }
  pair.camera.meta.eye = Eye::Pair;
  for (StageTiming& timing : ctx.timings) {
    timing.stage += " (right eye)";
    pair.timings.push_back(std::move(timing));
  }
  return pair;
}

}  // namespace arpipe
