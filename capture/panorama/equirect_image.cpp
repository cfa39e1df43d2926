#include "capture/panorama/equirect_image.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <stdexcept>

#include "capture/image_file.h"
#include "capture/panorama/panorama_file_kind.h"
#include "capture/panorama/stereo_eye_pixels.h"
#include "core/image/hdr_file.h"
#include "core/image/srgb.h"
#include "core/scene/asset_error.h"

namespace arpipe {

std::string EquirectImage::shape_problem(int width, int height) {
  if (width <= 0 || height <= 0) return fmt::format("an empty image ({} x {})", width, height);
  if (width != 2 * height) return fmt::format("{} x {} is not 2:1, as an equirectangular panorama is", width, height);
  if (height % 2 != 0) return fmt::format("{} x {}: the height must be even", width, height);
  if (width > EquirectImage::kMaxWidth)
    return fmt::format("{} x {} is wider than the limit of {} pixels", width, height, EquirectImage::kMaxWidth);
  return {};
}

EquirectImage::EquirectImage(std::vector<uint8_t> rgb, int width, int height, std::string name) : name_(std::move(name)) {
  if (const std::string why = shape_problem(width, height); !why.empty())
    throw std::invalid_argument(fmt::format("panorama \"{}\": {}", name_, why));
  if (rgb.size() != size_t(width) * size_t(height) * 3)
    throw std::invalid_argument(fmt::format("panorama \"{}\": {} bytes for {} x {} RGB", name_, rgb.size(), width, height));
  levels_.push_back({width, height, std::move(rgb)});
  for (int h = height; h % 2 == 0 && h / 2 >= kMaxSmallestLevelHeight; h /= 2) ++possible_levels_;
}

void EquirectImage::build_levels(int count) {
  // Each level the 2 x 2 mean of the one above; both sides stay even, so half a turn is a whole
  // number of texels at every level.
  while (built_levels() < std::min(count, possible_levels_)) {
    const Level& above = levels_.back();
    Level next{above.width / 2, above.height / 2, {}};
    next.rgb.resize(size_t(next.width) * size_t(next.height) * 3);
    for (int y = 0; y < next.height; ++y) {
      const uint8_t* top = above.rgb.data() + size_t(2 * y) * size_t(above.width) * 3;
      const uint8_t* bottom = top + size_t(above.width) * 3;
      uint8_t* out = next.rgb.data() + size_t(y) * size_t(next.width) * 3;
      for (int x = 0; x < next.width; ++x)
        for (int c = 0; c < 3; ++c) {
          const size_t i = size_t(6 * x + c);
          out[3 * x + c] = static_cast<uint8_t>((int(top[i]) + int(top[i + 3]) + int(bottom[i]) + int(bottom[i + 3]) + 2) / 4);
        }
    }
    levels_.push_back(std::move(next));
  }
}

std::string EquirectImage::shape_problem(PanoramaLayout layout, int width, int height) {
  switch (layout) {
    case PanoramaLayout::Auto: return shape_problem(layout_of_shape(width, height), width, height);
    case PanoramaLayout::Equirect: return shape_problem(width, height);
    case PanoramaLayout::EquirectTopBottom:
      if (width <= 0 || height <= 0 || height % 2 != 0 || width != height)
        return fmt::format("{} x {} is not 1:1 with an even height, as a top/bottom stereo pair of 2:1 panoramas is", width, height);
      return shape_problem(width, height / 2);
    case PanoramaLayout::EquirectLeftRight:
      if (width <= 0 || height <= 0 || width % 2 != 0 || width != 4 * height)
        return fmt::format("{} x {} is not 4:1, as a left/right stereo pair of 2:1 panoramas is", width, height);
      return shape_problem(width / 2, height);
  }
  return "an unknown layout";
}

std::vector<EquirectImage> EquirectImage::split(std::vector<uint8_t> rgb, int width, int height, PanoramaLayout layout,
                                                const std::string& name) {
  if (const std::string why = shape_problem(layout, width, height); !why.empty())
    throw std::invalid_argument(fmt::format("panorama \"{}\": {}", name, why));
  if (rgb.size() != size_t(width) * size_t(height) * 3)
    throw std::invalid_argument(fmt::format("panorama \"{}\": {} bytes for {} x {} RGB", name, rgb.size(), width, height));
  if (layout == PanoramaLayout::Auto) layout = layout_of_shape(width, height);
  std::vector<EquirectImage> eyes;
  if (layout == PanoramaLayout::Equirect) {
    eyes.emplace_back(std::move(rgb), width, height, name);
    return eyes;
  }
  const bool top_bottom = layout == PanoramaLayout::EquirectTopBottom;
  const int eye_width = top_bottom ? width : width / 2, eye_height = top_bottom ? height / 2 : height;
  for (int eye = 0; eye < 2; ++eye)
    eyes.emplace_back(stereo_eye_pixels(rgb, width, height, top_bottom, eye), eye_width, eye_height,
                      fmt::format("{} ({} eye)", name, eye == 0 ? "left" : "right"));
  return eyes;
}

EquirectImage EquirectImage::load(const std::filesystem::path& file, double hdr_scale) {
  return std::move(load_eyes(file, hdr_scale, PanoramaLayout::Equirect).front());
}

std::vector<EquirectImage> EquirectImage::load_eyes(const std::filesystem::path& file, double hdr_scale,
                                                    PanoramaLayout layout) {
  const std::string what = "panorama";
  if (panorama_file_kind(file) == PanoramaFileKind::Hdr) {
    const HdrImage hdr = read_hdr_image(file);
    if (const std::string why = shape_problem(layout, hdr.width, hdr.height); !why.empty())
      throw AssetError(fmt::format("{} \"{}\": {}", what, file.string(), why));
    std::vector<uint8_t> rgb(hdr.rgb.size());
    for (size_t i = 0; i < rgb.size(); ++i)
      rgb[i] = static_cast<uint8_t>(std::lround(255 * srgb_encode(std::clamp(double(hdr.rgb[i]) * hdr_scale, 0.0, 1.0))));
    return split(std::move(rgb), hdr.width, hdr.height, layout, file.string());
  }
  // A stereo pair holds two panoramas of the largest size.
  const int64_t eyes = layout == PanoramaLayout::Equirect ? 1 : 2;
  const ImageFileLimits limits{eyes * kMaxWidth, eyes * kMaxWidth * (kMaxWidth / 2), uint64_t(eyes) << 30};
  const cv::Mat bgr = read_image_file(file, what, limits);
  if (const std::string why = shape_problem(layout, bgr.cols, bgr.rows); !why.empty())
    throw AssetError(fmt::format("{} \"{}\": {}", what, file.string(), why));
  std::vector<uint8_t> rgb(size_t(bgr.cols) * size_t(bgr.rows) * 3);
  for (int y = 0; y < bgr.rows; ++y) {
    const uint8_t* in = bgr.ptr<uint8_t>(y);
    uint8_t* out = rgb.data() + size_t(y) * size_t(bgr.cols) * 3;
    for (int x = 0; x < bgr.cols; ++x) {
      out[3 * x] = in[3 * x + 2];
      out[3 * x + 1] = in[3 * x + 1];
      out[3 * x + 2] = in[3 * x];
    }
  }
  return split(std::move(rgb), bgr.cols, bgr.rows, layout, file.string());
}

const uint8_t* EquirectImage::texel(int level, int x, int y) const {
  const Level& l = levels_[static_cast<size_t>(level)];
  // Past a pole: the row mirrored back, half a turn round.
  if (y < 0) {
    y = -1 - y;
    x += l.width / 2;
  } else if (y >= l.height) {
    y = 2 * l.height - 1 - y;
    x += l.width / 2;
  }
  y = std::clamp(y, 0, l.height - 1);  // only for positions more than a whole image past a pole
  x %= l.width;
  if (x < 0) x += l.width;
  return l.rgb.data() + (size_t(y) * size_t(l.width) + size_t(x)) * 3;
}


}  // namespace arpipe
