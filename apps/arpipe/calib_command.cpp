// arpipe calib: finds the board in every image, solves the lens with mrcal, and writes the
// .cameramodel with its report, residual picture and the corners (for mrcal's own tools).
#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <exception>
#include <fstream>
#include <optional>
#include <thread>

#include "apps/arpipe/commands.h"
#include "apps/arpipe/progress_bar.h"
#include "calib/calibration_board.h"
#include "calib/calibration_images.h"
#include "calib/calibration_report.h"
#include "calib/calibration_run.h"
#include "calib/calibration_solver.h"
#include "calib/corners_vnl.h"
#include "calib/residual_image.h"
#include "core/log.h"

namespace arpipe {

namespace {
constexpr const char* kUsage =
    "usage: arpipe calib (--images 'GLOB' | --recording DIR) --board FILE --out CAMERA.cameramodel\n"
    "                    [--lensmodel NAME] [--focal PX] [--threads N] [--no-warp]\n"
    "  Finds the board (configs/boards/*.toml) in every image, solves the lens with mrcal and writes\n"
    "  CAMERA.cameramodel, and beside it CAMERA.report.txt, CAMERA.report.json, CAMERA.residuals.png\n"
    "  and CAMERA.corners.vnl (mrcal's corners cache). docs/CALIBRATION.md says how to take the images.\n"
    "  --lensmodel: LENSMODEL_OPENCV8 (default), OPENCV4, OPENCV5, PINHOLE, SPLINED_STEREOGRAPHIC\n"
    "               (configured automatically) or a full mrcal name; the LENSMODEL_ prefix is optional.\n"
    "  --focal: a focal-length guess in pixels (default: found from the views).\n";

template <typename T>
bool parse_number(const std::string& text, T& out) {
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), out);
  return ec == std::errc() && end == text.data() + text.size();
}

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
}  // namespace

int run_calib(const Args& args) {
  std::string images_glob;
  std::filesystem::path recording;
  std::filesystem::path board_path;
  std::filesystem::path out;
  calib::SolveOptions options;
  int threads = int(std::max(1u, std::thread::hardware_concurrency()));
  for (size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "--help" || args[i] == "-h") {
      std::fputs(kUsage, stdout);
      return 0;
    }
    if (args[i] == "--no-warp") {
      options.optimize_board_warp = false;
      continue;
    }
    if (i + 1 >= args.size()) {
      fmt::print(stderr, "arpipe calib: {} needs a value\n{}", args[i], kUsage);
      return 2;
    }
    const std::string& key = args[i];
    const std::string& value = args[++i];
    bool ok = true;
    if (key == "--images") images_glob = value;
    else if (key == "--recording") recording = value;
    else if (key == "--board") board_path = value;
    else if (key == "--out") out = value;
    else if (key == "--lensmodel") options.lensmodel = value.rfind("LENSMODEL_", 0) == 0 ? value : "LENSMODEL_" + value;
    else if (key == "--focal") ok = parse_number(value, options.focal_guess_px) && options.focal_guess_px > 0;
    else if (key == "--threads") ok = parse_number(value, threads) && threads > 0;
    else {
      fmt::print(stderr, "arpipe calib: unknown option {}\n{}", key, kUsage);
      return 2;
    }
    if (!ok) {
      fmt::print(stderr, "arpipe calib: bad value '{}' for {}\n{}", value, key, kUsage);
      return 2;
    }
  }
  if (images_glob.empty() == recording.empty() || board_path.empty() || out.empty()) {
    fmt::print(stderr, "arpipe calib: give one of --images and --recording, and --board and --out\n{}", kUsage);
    return 2;
  }

  try {
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
    result.model.save(out);
    std::fputs(calib::report_text(report).c_str(), stdout);
    log::info("wrote {} (and its report, residual picture and corners beside it)", out.string());
    return 0;
  } catch (const std::exception& e) {
    log::error("{}", e.what());
    return 1;
  }
}

}  // namespace arpipe
