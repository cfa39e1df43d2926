#include "capture/v4l2/v4l2_negotiation.h"

#include <linux/videodev2.h>

#include <cmath>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "capture/live/camera_stream.h"
#include "capture/v4l2/v4l2_frame_layout.h"
#include "core/pixel_format.h"

namespace arpipe {

bool is_mjpeg_fourcc(uint32_t fourcc) { return fourcc == V4L2_PIX_FMT_MJPEG || fourcc == V4L2_PIX_FMT_JPEG; }

bool same_rate(double fps, double wanted_fps) { return std::abs(fps - wanted_fps) <= 0.005 * wanted_fps; }

bool is_usable_fourcc(uint32_t fourcc) { return is_mjpeg_fourcc(fourcc) || v4l2_frame_layout(fourcc).has_value(); }

namespace {

std::string format_name(uint32_t fourcc) {
  if (is_mjpeg_fourcc(fourcc)) return "MJPG";
  if (const auto layout = v4l2_frame_layout(fourcc); layout && layout->name != CaptureFormat::Auto)
    return std::string(choice_name(kCaptureFormatNames, layout->name));
  if (const auto format = pixel_format_from_fourcc(fourcc)) return std::string(pixel_format_name(*format));
  return fourcc_text(fourcc);
}

bool format_matches(uint32_t fourcc, CaptureFormat wanted) {
  if (wanted == CaptureFormat::Auto) return is_usable_fourcc(fourcc);
  if (wanted == CaptureFormat::MJPG) return is_mjpeg_fourcc(fourcc);
  return fourcc == capture_format_fourcc(wanted);
}

// Auto's order: formats passed on as they are, then those reordered while copying, then MJPEG.
int auto_pass(uint32_t fourcc) {
  if (is_mjpeg_fourcc(fourcc)) return 2;
  const auto layout = v4l2_frame_layout(fourcc);
  return layout && layout->kind == V4L2FrameLayout::Kind::AsIs ? 0 : 1;
}

bool size_matches(const V4L2FrameSize& size, const V4L2FormatRequest& request) {
  return (request.width == 0 || size.width == uint32_t(request.width)) &&
         (request.height == 0 || size.height == uint32_t(request.height));
}

// A stepwise or continuous range (the note is set and the two ends are listed): any size inside it.
bool size_in_range(const V4L2FormatOffer& offer, const V4L2FormatRequest& request) {
  if (offer.note.empty() || offer.sizes.size() != 2 || request.width == 0 || request.height == 0) return false;
  const auto& big = offer.sizes[0];
  const auto& small = offer.sizes[1];
  return uint32_t(request.width) >= small.width && uint32_t(request.width) <= big.width &&
         uint32_t(request.height) >= small.height && uint32_t(request.height) <= big.height;
}

std::optional<V4L2Fraction> matching_interval(const V4L2FrameSize& size, double fps, bool& ok) {
  ok = true;
  if (size.intervals.empty()) {
    // Not enumerable (stepwise): ask for the rate and let the stream check the driver's answer.
    if (fps > 0) return V4L2Fraction{1000, uint32_t(std::lround(fps * 1000))};
    return std::nullopt;
  }
  if (fps <= 0) return size.intervals.front();
  for (const auto& interval : size.intervals)
    if (same_rate(interval.fps(), fps)) return interval;
  ok = false;
  return std::nullopt;
}

}  // namespace

std::string describe_v4l2_offers(const std::vector<V4L2FormatOffer>& offers) {
  std::string text;
  for (const auto& offer : offers) {
    const std::string usable = is_usable_fourcc(offer.fourcc) ? "" : " (not usable by arpipe)";
    if (!offer.note.empty()) text += fmt::format("  {} {}{}\n", format_name(offer.fourcc), offer.note, usable);
    for (const auto& size : offer.sizes) {
      std::vector<std::string> rates;
      for (const auto& interval : size.intervals) rates.push_back(fmt::format("{:.4g}", interval.fps()));
      const std::string rate_text =
          rates.empty() ? (size.note.empty() ? "" : " @ " + size.note) : fmt::format(" @ {} fps", fmt::join(rates, ", "));
      text += fmt::format("  {} {}x{}{}{}\n", format_name(offer.fourcc), size.width, size.height, rate_text, usable);
    }
  }
  if (text.empty()) text = "  (no formats listed)\n";
  return text;
}

V4L2FormatChoice choose_v4l2_format(const std::vector<V4L2FormatOffer>& offers, const V4L2FormatRequest& request,
                                    const std::string& device) {
  // Three passes for "auto" (auto_pass); one otherwise.
  for (int pass = 0; pass < 3; ++pass) {
    for (const auto& offer : offers) {
      if (!format_matches(offer.fourcc, request.pixel_format)) continue;
      if (request.pixel_format == CaptureFormat::Auto && auto_pass(offer.fourcc) != pass) continue;
      for (const auto& size : offer.sizes) {
        if (!size_matches(size, request)) continue;
        bool ok = false;
        const auto interval = matching_interval(size, request.fps, ok);
        if (ok) return {offer.fourcc, size.width, size.height, interval};
      }
      if (size_in_range(offer, request)) {
        V4L2FrameSize size{uint32_t(request.width), uint32_t(request.height), {}, {}};
        bool ok = false;
        const auto interval = matching_interval(size, request.fps, ok);
        return {offer.fourcc, size.width, size.height, interval};
      }
    }
    if (request.pixel_format != CaptureFormat::Auto) break;
  }
  const std::string size = request.width || request.height
                               ? fmt::format("{}x{}", request.width ? fmt::format("{}", request.width) : "any",
                                             request.height ? fmt::format("{}", request.height) : "any")
                               : "any size";
  const std::string rate = request.fps > 0 ? fmt::format("{:.4g} fps", request.fps) : "any rate";
  throw CameraError(CameraError::Kind::Refused,
                    fmt::format("{}: cannot capture {} {} at {}; the camera offers:\n{}", device,
                                choice_name(kCaptureFormatNames, request.pixel_format),
                                size, rate, describe_v4l2_offers(offers)));
}

}  // namespace arpipe
