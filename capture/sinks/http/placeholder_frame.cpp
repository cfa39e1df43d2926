#include "capture/sinks/http/placeholder_frame.h"

#include <algorithm>
#include <string>

#include <opencv2/imgproc.hpp>

namespace arpipe {

Frame placeholder_frame(int width, int height, std::string_view text) {
  width = std::clamp(width, 64, 8192);
  height = std::clamp(height, 64, 8192);
  Frame frame = Frame::allocate(PixelFormat::RGB24, width, height);
  cv::Mat image(height, width, CV_8UC3, frame.data.data(), frame.bytes_per_line);
  image.setTo(cv::Scalar(48, 48, 48));
  const std::string line(text);
  const int font = cv::FONT_HERSHEY_SIMPLEX;
  const int thickness = std::max(1, width / 400);
  // As large as fits in nine tenths of the width.
  int baseline = 0;
  const cv::Size unit = cv::getTextSize(line, font, 1.0, thickness, &baseline);
  const double scale = std::clamp(0.9 * width / std::max(1, unit.width), 0.3, 3.0);
  const cv::Size size = cv::getTextSize(line, font, scale, thickness, &baseline);
  cv::putText(image, line, cv::Point((width - size.width) / 2, (height + size.height) / 2), font, scale,
              cv::Scalar(235, 235, 235), thickness, cv::LINE_AA);
  return frame;
}

}  // namespace arpipe
