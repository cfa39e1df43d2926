// Corners judged by their neighbours' homography (see grid_consistency.h).
#include "calib/grid_consistency.h"

#include <opencv2/calib3d.hpp>

#include <cmath>

namespace arpipe::calib {
namespace {

// Fewer seen neighbours than this within two squares and the corner is not judged: 4 is what a
// homography needs, more keep one wrong neighbour from deciding.
constexpr size_t kMinNeighbours = 6;

}  // namespace

OffGridCorner farthest_off_grid(int rows, int cols, const std::vector<Vec2>& pixels, const std::vector<double>& weights) {
  const auto seen = [&](int r, int c) {
    return r >= 0 && r < rows && c >= 0 && c < cols && weights[size_t(r * cols + c)] > 0;
  };
  OffGridCorner worst;
  std::vector<cv::Point2d> board, image;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      if (!seen(r, c)) continue;
      // The nearest ring that holds enough seen neighbours: the 3 x 3, else the 5 x 5.
      for (int reach = 1; reach <= 2; ++reach) {
        board.clear();
        image.clear();
        for (int dr = -reach; dr <= reach; ++dr)
          for (int dc = -reach; dc <= reach; ++dc)
            if ((dr != 0 || dc != 0) && seen(r + dr, c + dc)) {
              board.emplace_back(c + dc, r + dr);
              const Vec2& q = pixels[size_t((r + dr) * cols + c + dc)];
              image.emplace_back(q[0], q[1]);
            }
        if (board.size() >= kMinNeighbours) break;
      }
      if (board.size() < kMinNeighbours) continue;
      cv::Mat H;
      try {
        H = cv::findHomography(board, image, 0);  // least squares over all of them
      } catch (const cv::Exception&) {  // degenerate neighbours (all on one line): not judged
        continue;
      }
      if (H.empty()) continue;
      const auto map = [&H](double x, double y) {
        const double w = H.at<double>(2, 0) * x + H.at<double>(2, 1) * y + H.at<double>(2, 2);
        return Vec2{(H.at<double>(0, 0) * x + H.at<double>(0, 1) * y + H.at<double>(0, 2)) / w,
                    (H.at<double>(1, 0) * x + H.at<double>(1, 1) * y + H.at<double>(1, 2)) / w};
      };
      const Vec2 predicted = map(c, r);
      const Vec2 right = map(c + 1, r), down = map(c, r + 1);
      const double square = 0.5 * (std::hypot(right[0] - predicted[0], right[1] - predicted[1]) +
                                   std::hypot(down[0] - predicted[0], down[1] - predicted[1]));
      const Vec2& p = pixels[size_t(r * cols + c)];
      const double share = std::hypot(p[0] - predicted[0], p[1] - predicted[1]) / square;
      if (std::isfinite(share) && share > worst.share) worst = {r * cols + c, share};
    }
  return worst;
}

int drop_off_grid_corners(int rows, int cols, const std::vector<Vec2>& pixels, std::vector<double>& weights) {
  int dropped = 0;
  for (;;) {
    const OffGridCorner worst = farthest_off_grid(rows, cols, pixels, weights);
    if (worst.index < 0 || worst.share <= kMaxOffGridShare) return dropped;
    weights[size_t(worst.index)] = -1.0;
    ++dropped;
  }
}

}  // namespace arpipe::calib
