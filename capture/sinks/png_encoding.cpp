#include "capture/sinks/png_encoding.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace arpipe {

std::vector<uint8_t> encode_png(const Frame& rgb, int compression) {
  const cv::Mat image(rgb.height, rgb.width, CV_8UC3, const_cast<uint8_t*>(rgb.data.data()), rgb.bytes_per_line);
  cv::Mat bgr;
  cv::cvtColor(image, bgr, cv::COLOR_RGB2BGR);
  // Level 1 is OpenCV's default, which also picks its fast filter and strategy: naming the level
  // would switch those, so the default stays unnamed.
  std::vector<int> params;
  if (compression != 1) params = {cv::IMWRITE_PNG_COMPRESSION, compression};
  std::vector<uint8_t> png;
  if (!cv::imencode(".png", bgr, png, params)) throw std::runtime_error("the PNG encoder refused the frame");
  return png;
}

}  // namespace arpipe
