#include "calib/board_detection_set.h"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <exception>
#include <mutex>
#include <optional>
#include <thread>

#include "calib/board_detector.h"
#include "core/geometry/camera_model.h"

namespace arpipe::calib {
namespace {

struct ImageOutcome {
  int width = 0;
  int height = 0;
  std::optional<BoardObservation> view;
};

// When the board is found nowhere, the file is the usual suspect: squares counted instead of inner
// corners, rows and columns swapped, one off. Tries those sizes on a few images and names a match.
std::string guess_other_chessboard(const CalibrationImages& images, const CalibrationBoard& board) {
  if (board.kind != BoardKind::chessboard) return {};
  std::vector<std::pair<int, int>> sizes;
  for (int dr = -1; dr <= 1; ++dr)
    for (int dc = -1; dc <= 1; ++dc)
      if (dr || dc) sizes.emplace_back(board.rows + dr, board.cols + dc);
  sizes.emplace_back(board.cols, board.rows);
  const size_t tries = std::min<size_t>(images.count(), 3);
  for (const auto& [rows, cols] : sizes) {
    if (rows < 2 || cols < 2) continue;
    CalibrationBoard other = board;
    other.rows = rows;
    other.cols = cols;
    BoardDetector detector(other);
    for (size_t i = 0; i < tries; ++i) {
      const GreyImage image = images.load(i);
      if (detector.detect(image.pixels.data(), image.width, image.height, size_t(image.width), image.name))
        return fmt::format(
            "; {} shows a chessboard of {} x {} inner corners: set inner_corners = [{}, {}] in the board file "
            "(inner corners are one fewer than squares each way)",
            image.name, rows, cols, rows, cols);
    }
  }
  return {};
}

bool error_flag(std::mutex& mutex, const std::exception_ptr& error) {
  const std::lock_guard lock(mutex);
  return bool(error);
}

}  // namespace

DetectionSet detect_boards(const CalibrationImages& images, const CalibrationBoard& board, int threads,
                           const std::function<void(int, int)>& progress, const CameraModel* lens) {
  const int total = int(images.count());
  std::vector<ImageOutcome> outcomes(static_cast<size_t>(total));
  std::atomic<int> next{0};
  std::atomic<int> done{0};
  std::mutex error_mutex;
  std::exception_ptr error;
  auto worker = [&] {
    BoardDetector detector(board);  // one per thread: detectors are not shared
    for (int i = next++; i < total; i = next++) {
      try {
        const GreyImage image = images.load(size_t(i));
        ImageOutcome& out = outcomes[size_t(i)];
        out.width = image.width;
        out.height = image.height;
        out.view = lens ? detector.detect(image.pixels.data(), image.width, image.height, size_t(image.width),
                                          image.name, *lens)
                        : detector.detect(image.pixels.data(), image.width, image.height, size_t(image.width), image.name);
      } catch (...) {
        const std::lock_guard lock(error_mutex);
        if (!error) error = std::current_exception();
        next = total;  // stop the others early
      }
      ++done;
    }
  };
  const int workers = std::clamp(threads, 1, std::max(1, total));
  std::vector<std::thread> pool;
  for (int t = 0; t < workers; ++t) pool.emplace_back(worker);
  // The calling thread only reports progress, so a progress bar needs no locking.
  for (int reported = -1; done < total && !error_flag(error_mutex, error);) {
    if (progress && done != reported) progress(reported = done, total);
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  for (auto& thread : pool) thread.join();
  if (progress) progress(done, total);
  if (error) std::rethrow_exception(error);

  DetectionSet set;
  set.images = total;
  for (int i = 0; i < total; ++i) {
    const ImageOutcome& out = outcomes[size_t(i)];
    if (i == 0) {
      set.width = out.width;
      set.height = out.height;
    } else if (out.width != set.width || out.height != set.height) {
      throw CalibrationInputError(fmt::format(
          "{} is {}x{} but {} is {}x{}: calibrate one camera mode at a time (the lens model belongs to one image "
          "size)",
          images.name(size_t(i)), out.width, out.height, images.name(0), set.width, set.height));
    }
    if (out.view)
      set.views.push_back(*out.view);
    else
      set.without_board.push_back(images.name(size_t(i)));
  }
  if (set.views.empty())
    throw CalibrationInputError(fmt::format(
        "the board ({} x {} points) was found in none of the {} images{}", board.rows, board.cols, total,
        board.kind == BoardKind::chessboard ? guess_other_chessboard(images, board)
        : board.kind == BoardKind::charuco
            ? fmt::format("; check the dictionary ({}) and the squares ({} x {}) in the board file, and that at least "
                          "12 corners show",
                          board.dictionary, board.rows + 1, board.cols + 1)
            : "; check the tag family, size and first id in the board file"));
  return set;
}

}  // namespace arpipe::calib
