// arpipe calib: finds the board in every image, solves the lens with mrcal, and writes the
// .cameramodel with its report, residual picture and the corners (for mrcal's own tools).
#include <fmt/format.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>
#include <thread>

#include "apps/arpipe/commands.h"
#include "apps/cli/command_line.h"
#include "apps/cli/progress_bar.h"
#include "calib/calibration_board.h"
#include "calib/calibration_images.h"
#include "calib/calibration_report.h"
#include "calib/calibration_run.h"
#include "calib/calibration_solver.h"
#include "calib/corners_vnl.h"
#include "calib/optimization_inputs.h"
#include "calib/residual_image.h"
#include "core/log.h"

namespace arpipe {

namespace {

std::filesystem::path beside(const std::filesystem::path& model, const std::string& suffix) {
  std::filesystem::path p = model;
  p.replace_extension();
  return p.string() + suffix;
}

void write_text(const std::filesystem::path& path, const std::string& text) {
  const std::filesystem::path temporary = path.string() + ".tmp";
  {
    std::ofstream out(temporary, std::ios::binary);
    out << text;
    if (!out.flush()) throw calib::CalibrationInputError(fmt::format("{}: cannot write", path.string()));
  }
  std::filesystem::rename(temporary, path);
}
struct CalibOptions {
  std::string images_glob;
  std::filesystem::path recording, board_path, out;
  calib::SolveOptions solve;
  int threads = int(std::max(1u, std::thread::hardware_concurrency()));
};

int calibrate(const CalibOptions& command) {
  const std::string& images_glob = command.images_glob;
  const std::filesystem::path& recording = command.recording;
  const std::filesystem::path& board_path = command.board_path;
  const std::filesystem::path& out = command.out;
  calib::SolveOptions options = command.solve;
  if (options.lensmodel.rfind("LENSMODEL_", 0) != 0) options.lensmodel = "LENSMODEL_" + options.lensmodel;
  const int threads = command.threads;
  const calib::CalibrationBoard board = calib::load_board(board_path);
  const auto images = images_glob.empty() ? calib::images_from_recording(recording)
                                          : calib::images_from_glob(images_glob);
  std::optional<ProgressBar> bars[2];  // made when their pass starts: the bar times from its creation
  calib::CalibrationRunProgress progress;
  progress.detection = [&bars](int pass, int done, int total) {
    std::optional<ProgressBar>& bar = bars[pass == 1 ? 0 : 1];
    if (!bar) bar.emplace(pass == 1 ? "images" : "images (tag centres through the first solve's lens)");
    bar->update(done, total);
    if (done == total) bar->finish();
  };
  progress.solve = [](int stage, int stages, const std::string& name) {
    log::info("solve stage {}/{}: {}", stage + 1, stages, name);
  };
  const calib::CalibrationRun run = calib::run_calibration(*images, board, options, threads, progress);
  const calib::DetectionSet& found = run.found;
  const calib::CalibrationResult& result = run.result;
  log::info("found the board in {} of {} images ({}x{})", found.views.size(), found.images, found.width,
            found.height);
  if (run.first_pass_rms_per_point_px)
    log::info("second pass with the lens: RMS per point {:.3f} px (first pass {:.3f} px)", result.rms_per_point_px,
              *run.first_pass_rms_per_point_px);
  const calib::CalibrationReport report = calib::make_report(result, found.images, found.without_board);

  // The model last: a failure writing the extras leaves no model that looks finished.
  calib::write_corners_vnl(beside(out, ".corners.vnl"), found.views, board);  // as detected: mrcal redoes its own outlier rejection
  write_text(beside(out, ".report.txt"), calib::report_text(report));
  write_text(beside(out, ".report.json"), calib::report_json(report));
  calib::write_residual_image(beside(out, ".residuals.png"), result);
  // With mrcal's optimization_inputs, so its uncertainty, residual and culling tools read the solve.
  calib::save_model_with_optimization_inputs(result, out);
  std::fputs(calib::report_text(report).c_str(), stdout);
  log::info("wrote {} (and its report, residual picture and corners beside it)", out.string());
  return 0;
}

}  // namespace

void add_calib_command(CLI::App& arpipe) {
  CLI::App* command = arpipe.add_subcommand(
      "calib", "calibrate a camera's lens with mrcal from views of a board (configs/boards/), with a report");
  command->footer(
      "Finds the board in every image, solves the lens with mrcal and writes CAMERA.cameramodel (with mrcal's\n"
      "optimization_inputs, for mrcal-show-projection-uncertainty and friends), and beside it\n"
      "CAMERA.report.txt, CAMERA.report.json, CAMERA.residuals.png and CAMERA.corners.vnl (mrcal's corners\n"
      "cache). docs/CALIBRATION.md says how to take the images.");
  auto options = std::make_shared<CalibOptions>();
  CLI::Option* images = command->add_option("--images", options->images_glob, "the images (quote the pattern)")
                            ->type_name("GLOB");
  CLI::Option* recording = command->add_option("--recording", options->recording, "a recording's frames")
                               ->type_name("DIR");
  images->excludes(recording);
  // Required, like one of --images and --recording: checked together below, one message for all.
  command->add_option("--board", options->board_path, "the board file (configs/boards/*.toml); required")
      ->type_name("FILE");
  command->add_option("--out", options->out, "the camera model to write; required")->type_name("CAMERA.cameramodel");
  command->add_option("--lensmodel", options->solve.lensmodel,
                      "OPENCV8, OPENCV4, OPENCV5, PINHOLE, SPLINED_STEREOGRAPHIC (configured automatically) or a full "
                      "mrcal name; the LENSMODEL_ prefix is optional")
      ->type_name("NAME");
  command->add_option("--focal", options->solve.focal_guess_px, "a focal-length guess in pixels")
      ->type_name("PX")
      ->check(CLI::PositiveNumber)
      ->default_str("found from the views");
  command->add_option("--threads", options->threads, "detection threads")->check(CLI::PositiveNumber);
  command->add_flag_function("--no-warp", [options](int64_t) { options->solve.optimize_board_warp = false; },
                             "do not solve for the board's warp");
  cli::on_run(command, [options, images, recording] {
    if ((!*images && !*recording) || options->board_path.empty() || options->out.empty())
      cli::usage_error("give one of --images and --recording, and --board and --out");
    return calibrate(*options);
  }, cli::Failure{.status = 1});
}

}  // namespace arpipe
