#include "calib/board_printout.h"

#include <apriltag/apriltag.h>
#include <fmt/format.h>

#include <cmath>
#include <opencv2/aruco/charuco.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/track/tag_family.h"

namespace arpipe::calib {
namespace {

constexpr double kMetresPerInch = 0.0254;

// Chessboard: (rows + 1) x (cols + 1) squares, the top-left one dark, and one square of white
// around them (detectors need a light border).
cv::Mat draw_chessboard(const CalibrationBoard& board, double px_per_m) {
  const int squares_x = board.cols + 1;
  const int squares_y = board.rows + 1;
  const auto at = [&](double metres) { return int(std::lround(metres * px_per_m)); };
  const double s = board.spacing_m;
  cv::Mat image(at((squares_y + 2) * s), at((squares_x + 2) * s), CV_8UC1, cv::Scalar(255));
  for (int y = 0; y < squares_y; ++y)
    for (int x = 0; x < squares_x; ++x)
      if ((x + y) % 2 == 0)
        cv::rectangle(image, cv::Point(at((x + 1) * s), at((y + 1) * s)),
                      cv::Point(at((x + 2) * s) - 1, at((y + 2) * s) - 1), cv::Scalar(0), cv::FILLED);
  return image;
}

// AprilTag grid: tag (row, col) has id first_id + row * cols + col, row 0 at the top of the page,
// as the detector numbers them. Each tag is drawn from libapriltag's own bit pattern.
cv::Mat draw_apriltag_grid(const CalibrationBoard& board, double px_per_m) {
  TagFamilyPtr family = create_tag_family(board.family);
  if (!family) throw BoardError(fmt::format("{}: unknown tag family \"{}\"", board.name, board.family));
  const int border_cells = family->width_at_border;
  const int total_cells = family->total_width;
  const double cell_m = board.tag_size_m / border_cells;
  const double gap_m = board.spacing_m - board.tag_size_m;
  const double margin_m = gap_m + cell_m;  // beyond the outer tags' own white border
  const auto at = [&](double metres) { return int(std::lround(metres * px_per_m)); };
  const double width_m = 2 * margin_m + (board.cols - 1) * board.spacing_m + board.tag_size_m;
  const double height_m = 2 * margin_m + (board.rows - 1) * board.spacing_m + board.tag_size_m;
  cv::Mat image(at(height_m), at(width_m), CV_8UC1, cv::Scalar(255));
  const int offset_cells = (total_cells - border_cells) / 2;  // white cells around the black border
  for (int row = 0; row < board.rows; ++row)
    for (int col = 0; col < board.cols; ++col) {
      const int id = board.first_id + row * board.cols + col;
      if (id >= int(family->ncodes))
        throw BoardError(fmt::format("{}: tag id {} is beyond {}'s {} codes", board.name, id, board.family,
                                     family->ncodes));
      image_u8_t* tag = apriltag_to_image(family.get(), uint32_t(id));
      const double left = margin_m + col * board.spacing_m - offset_cells * cell_m;
      const double top = margin_m + row * board.spacing_m - offset_cells * cell_m;
      for (int cy = 0; cy < tag->height; ++cy)
        for (int cx = 0; cx < tag->width; ++cx)
          if (tag->buf[cy * tag->stride + cx] < 128)
            cv::rectangle(image, cv::Point(at(left + cx * cell_m), at(top + cy * cell_m)),
                          cv::Point(at(left + (cx + 1) * cell_m) - 1, at(top + (cy + 1) * cell_m) - 1), cv::Scalar(0),
                          cv::FILLED);
      image_u8_destroy(tag);
    }
  return image;
}

// ChArUco: the chessboard above (top-left square dark) with a marker drawn by OpenCV
// (cv::aruco::drawMarker, one black border bit) centred in each light square, marker i in the i-th
// light square along the rows: cv::aruco::CharucoBoard's layout, so its interpolation numbers the
// inner corners row by row. Every edge is rounded to whole pixels like the chessboard's, so the
// squares are exact to the pixel at any dpi (CharucoBoard::draw scales the board to one size).
cv::Mat draw_charuco(const CalibrationBoard& board, double px_per_m) {
  cv::Mat image = draw_chessboard(board, px_per_m);
  const auto at = [&](double metres) { return int(std::lround(metres * px_per_m)); };
  const double s = board.spacing_m;
  const double inset = (s - board.marker_m) / 2;
  const cv::Ptr<cv::aruco::Dictionary> dictionary = cv::aruco::getPredefinedDictionary(board.dictionary_id);
  int id = 0;
  for (int y = 0; y <= board.rows; ++y)
    for (int x = 0; x <= board.cols; ++x) {
      if ((x + y) % 2 == 0) continue;  // dark square
      const int left = at((x + 1) * s + inset);
      const int top = at((y + 1) * s + inset);
      const int side = std::min(at((x + 1) * s + inset + board.marker_m) - left,
                                at((y + 1) * s + inset + board.marker_m) - top);
      if (id >= dictionary->bytesList.rows)
        throw BoardError(fmt::format("{}: {} has no marker {}", board.name, board.dictionary, id));
      cv::Mat marker;
      cv::aruco::drawMarker(dictionary, id++, side, marker, 1);
      marker.copyTo(image(cv::Rect(left, top, side, side)));
    }
  return image;
}

}  // namespace

PrintedBoard write_board_png(const CalibrationBoard& board, const std::filesystem::path& png, double dots_per_inch) {
  if (!(dots_per_inch >= 50 && dots_per_inch <= 2400))
    throw BoardError(fmt::format("{}: {} dots per inch is not a printer's resolution (50 to 2400)", png.string(),
                                 dots_per_inch));
  const double px_per_m = dots_per_inch / kMetresPerInch;
  const cv::Mat image = board.kind == BoardKind::chessboard ? draw_chessboard(board, px_per_m)
                         : board.kind == BoardKind::charuco  ? draw_charuco(board, px_per_m)
                                                             : draw_apriltag_grid(board, px_per_m);
  bool written = false;
  try {
    written = cv::imwrite(png.string(), image);
  } catch (const cv::Exception& e) {
    throw BoardError(fmt::format("{}: cannot write the board picture: {}", png.string(), e.what()));
  }
  if (!written) throw BoardError(fmt::format("{}: cannot write the board picture", png.string()));
  return {image.cols, image.rows, image.cols / px_per_m, image.rows / px_per_m};
}

}  // namespace arpipe::calib
