// Benchmark: chessboard detection and corner accuracy against the simulator's truth, for each
// corner refinement (the finder's own corners, cornerSubPix, cornerSubPix + the X-junction model
// fit) and each chessboard finder alone, with the time per image; and the views that OpenCV's
// finders with their default flags find and arpipe's cascade loses (issue 25's bar: none). The capture must be the calib-board scene or share its board layout (9 x 13 inner
// corners of 20 mm at x = -0.12 + 0.02 i, y = 0.08 - 0.02 j in the world).
// `arpipe bench calib-corners [--recording DIR] [--board FILE] [--dump FILE]` prints a markdown
// table for docs/BENCHMARKS.md. Defaults: build/calib-capture, configs/boards/chessboard-10x14-20mm.toml.
// --dump writes every corner (refinement, frame, point, true and detected pixel) as a vnl table.
#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <opencv2/calib3d.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "apps/cli/command_line.h"
#include "bench/benchmarks.h"
#include "calib/board_detector.h"
#include "calib/calibration_board.h"
#include "calib/calibration_images.h"
#include "capture/recording/recording_reader.h"
#include "core/log.h"
#include "core/pipeline/monotonic_clock.h"

namespace arpipe {
namespace {

using namespace arpipe::calib;

std::vector<Vec3> board_corners_in_world() {
  std::vector<Vec3> out;
  for (int j = 0; j < 9; ++j)
    for (int i = 0; i < 13; ++i) out.push_back({-0.12 + 0.02 * i, 0.08 - 0.02 * j, 0.0});
  return out;
}

struct Errors {
  int frames_found = 0, points = 0;
  double sum_dx = 0, sum_dy = 0, sum2 = 0, max_px = 0, ms = 0;
};

const char* name(CornerRefinement refinement) {
  switch (refinement) {
    case CornerRefinement::none: return "the finder's own corners";
    case CornerRefinement::corner_subpix: return "cornerSubPix";
    case CornerRefinement::model_fit: return "cornerSubPix + X-junction model fit";
  }
  return "?";
}

struct CornersOptions {
  std::string recording = "build/calib-capture", board_file = "configs/boards/chessboard-10x14-20mm.toml", dump_file;
};

int run_calib_corners_benchmark(const CornersOptions& options) {
  const std::string& recording = options.recording;
  const std::string& board_file = options.board_file;
  const std::string& dump_file = options.dump_file;
  log::set_max_level(log::Level::Warning);
  try {
    RecordingReader reader(recording);
    const auto images = images_from_recording(recording);
    if (reader.ground_truth().size() != reader.frame_count())
      throw std::runtime_error(recording + ": no ground truth for every frame (not a simulated capture?)");
    const CalibrationBoard board = load_board(board_file);
    const std::vector<Vec3> world = board_corners_in_world();
    std::FILE* dump = dump_file.empty() ? nullptr : std::fopen(dump_file.c_str(), "w");
    if (!dump_file.empty() && !dump) throw std::runtime_error(dump_file + ": cannot write");
    if (dump) fmt::print(dump, "# refinement frame point x_true y_true x y\n");
    fmt::print("Corners against the truth on {} ({} frames, board {}):\n\n", recording, reader.frame_count(), board_file);
    fmt::print("| finder | refinement | boards found | RMS per coordinate | mean error x, y | largest error | ms per image |\n");
    fmt::print("|---|---|---|---|---|---|---|\n");
    // The cascade with each refinement, then each finder alone with the full refinement.
    struct Row {
      std::vector<ChessboardFinder> finders;  // empty: the cascade
      CornerRefinement refinement;
    };
    std::vector<Row> rows{{{}, CornerRefinement::none}, {{}, CornerRefinement::corner_subpix}, {{}, CornerRefinement::model_fit}};
    for (ChessboardFinder finder : chessboard_finders(board)) rows.push_back({{finder}, CornerRefinement::model_fit});
    std::vector<bool> cascade_found(reader.frame_count(), false);
    for (const auto& [finders, refinement] : rows) {
      const BoardDetector detector(board, refinement, finders);
      const std::string finder_name = finders.empty() ? "the cascade" : chessboard_finder_name(finders.front());
      Errors e;
      for (size_t f = 0; f < reader.frame_count(); ++f) {
        const GreyImage image = images->load(f);
        const auto start = std::chrono::steady_clock::now();
        const auto observation = detector.detect(image.pixels.data(), image.width, image.height, size_t(image.width), image.name);
        e.ms += milliseconds_since(start);
        if (!observation) continue;
        ++e.frames_found;
        if (finders.empty()) cascade_found[f] = true;
        const SE3& T_cam_world = reader.ground_truth().at(f).T_cam_world_mid;
        for (size_t i = 0; i < world.size() && i < observation->pixels.size(); ++i) {
          const auto truth = reader.camera_model().project(T_cam_world * world[i]);
          if (observation->weights[i] <= 0 || !truth) continue;
          const double dx = observation->pixels[i][0] - (*truth)[0], dy = observation->pixels[i][1] - (*truth)[1];
          e.sum_dx += dx, e.sum_dy += dy, e.sum2 += dx * dx + dy * dy, ++e.points;
          e.max_px = std::max(e.max_px, std::hypot(dx, dy));
          if (dump)
            fmt::print(dump, "{} {} {} {:.4f} {:.4f} {:.4f} {:.4f}\n", int(refinement), f, i, (*truth)[0], (*truth)[1],
                       observation->pixels[i][0], observation->pixels[i][1]);
        }
      }
      const double n = std::max(e.points, 1);
      fmt::print("| {} | {} | {} of {} | {:.3f} px | {:+.3f}, {:+.3f} px | {:.2f} px | {:.1f} |\n", finder_name,
                 name(refinement), e.frames_found, reader.frame_count(), std::sqrt(e.sum2 / (2 * n)), e.sum_dx / n, e.sum_dy / n, e.max_px,
                 e.ms / double(reader.frame_count()));
    }
    // The independent references: OpenCV's finders with their default flags, as a user would call
    // them. A view either finds that the cascade misses is a view lost.
    int classic_found = 0, sb_found = 0, lost = 0;
    std::string lost_names;
    for (size_t f = 0; f < reader.frame_count(); ++f) {
      const GreyImage image = images->load(f);
      const cv::Mat grey(image.height, image.width, CV_8UC1, const_cast<uint8_t*>(image.pixels.data()));
      std::vector<cv::Point2f> corners;
      const bool classic = cv::findChessboardCorners(grey, cv::Size(board.cols, board.rows), corners);
      const bool sb = cv::findChessboardCornersSB(grey, cv::Size(board.cols, board.rows), corners);
      classic_found += classic;
      sb_found += sb;
      if ((classic || sb) && !cascade_found[f]) {
        ++lost;
        lost_names += " " + image.name;
      }
    }
    fmt::print("\nOpenCV's findChessboardCorners with its default flags found {} of {}, findChessboardCornersSB {} of {};"
               " views either found that the cascade lost: {}{}\n",
               classic_found, reader.frame_count(), sb_found, reader.frame_count(), lost, lost_names);
    if (dump) std::fclose(dump);
  } catch (const std::exception& error) {
    fmt::print(stderr, "arpipe bench calib-corners: {}\n", error.what());
    return 1;
  }
  return 0;
}

}  // namespace

void add_calib_corners_benchmark(CLI::App& bench) {
  CLI::App* command = bench.add_subcommand(
      "calib-corners", "chessboard corner accuracy against the simulator's truth for each corner refinement, with time");
  auto options = std::make_shared<CornersOptions>();
  command->add_option("--recording", options->recording, "the calib-board capture, or one with its board layout and truth")
      ->type_name("DIR");
  command->add_option("--board", options->board_file, "the board file")->type_name("FILE");
  command->add_option("--dump", options->dump_file, "write every corner (refinement, frame, point, true and detected pixel) as a vnl table")
      ->type_name("FILE");
  cli::on_run(command, [options] { return run_calib_corners_benchmark(*options); }, cli::Failure{});
}

}  // namespace arpipe
