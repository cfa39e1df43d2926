// mrcal's own tools on what `arpipe calib` writes (the simulator's calib-board capture): the model's
// optimization_inputs are the solve arpipe ran (mrcal.optimize takes no step from them), mrcal's
// uncertainty agrees with arpipe's report, and mrcal-show-projection-uncertainty,
// mrcal-show-residuals-board-observation and mrcal-cull-corners run on it headless.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "tests/support/printed_numbers.h"
#include "core/geometry/camera_model.h"
#include "tests/e2e/child_process.h"

namespace fs = std::filesystem;
using namespace arpipe;

namespace {

const fs::path kCapture = fs::path(ARPIPE_BINARY_DIR) / "calib-capture";
const fs::path kBoard = fs::path(ARPIPE_SOURCE_DIR) / "configs/boards/chessboard-10x14-20mm.toml";
const fs::path kPython = "/usr/bin/python3";  // Debian's, where python3-mrcal lives (not a pyenv's)

// Prints, for the model and its report: whether the intrinsics stored in optimization_inputs equal
// the model's bit for bit; the largest change mrcal.optimize makes to them when re-run on the stored
// inputs; and mrcal.projection_uncertainty (at infinity, worst direction) at the report's grid.
constexpr const char* kCheckScript = R"(
import sys, json, numpy as np, mrcal
m = mrcal.cameramodel(sys.argv[1])
report = json.load(open(sys.argv[2]))
inputs = m.optimization_inputs()
stored = inputs['intrinsics'][0].copy()
print("stored_equals_model", int(np.array_equal(stored, m.intrinsics()[1])))
print("observations", inputs['observations_board'].shape[0])
stats = mrcal.optimize(**inputs)
print("reoptimized_change", repr(float(np.max(np.abs(inputs['intrinsics'][0] - stored)))))
print("reoptimized_rms", repr(float(stats['rms_reproj_error__pixels'])))
q = np.array(report['projection_uncertainty_grid']['pixels'], dtype=float)
v = mrcal.unproject(q, *m.intrinsics(), normalize=True)
u = mrcal.projection_uncertainty(v, m, atinfinity=True, what='worstdirection-stdev')
print("uncertainty", " ".join(repr(float(x)) for x in u))
)";

using arpipe::test::numbers_after;

// Runs a shell command in dir; returns its exit status (-1 when it did not exit normally).
int shell(const fs::path& dir, const std::string& command) {
  const int status = std::system(fmt::format("cd '{}' && {}", dir.string(), command).c_str());
  return status != -1 && WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

class ArpipeCalibMrcalTools : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override {
    for (const char* tool : {"mrcal-show-projection-uncertainty", "mrcal-show-residuals-board-observation",
                             "mrcal-cull-corners", "gnuplot"})
      if (!fs::exists(fs::path("/usr/bin") / tool)) GTEST_SKIP() << tool << " is not installed (scripts/install-deps.sh)";
    if (shell("/", kPython.string() + " -c 'import mrcal' 2>/dev/null") != 0)
      GTEST_SKIP() << "python3-mrcal is not installed (scripts/install-deps.sh)";
    dir_ = fs::path(ARPIPE_BINARY_DIR) / "e2e-out" / "ArpipeCalibMrcalTools" / GetParam();
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  fs::path dir_;
};

TEST_P(ArpipeCalibMrcalTools, ReadTheModelArpipeWrote) {
  const fs::path model_path = dir_ / "camera.cameramodel";
  {
    test::ChildProcess child(test::build_program("arpipe"),
                             {"calib", "--recording", kCapture.string(), "--board", kBoard.string(), "--lensmodel",
                              GetParam(), "--out", model_path.string()},
                             dir_ / "logs");
    const int status = child.wait(std::chrono::seconds(300));
    ASSERT_TRUE(status != -1 && WIFEXITED(status) && WEXITSTATUS(status) == 0) << child.stderr_text();
  }
  const nlohmann::json report = nlohmann::json::parse(test::read_text(dir_ / "camera.report.json"));

  // arpipe's own reader still reads the model (optimization_inputs are a b'' string it skips), and
  // the intrinsics are what the solve gave, to the last bit (%.17g).
  const CameraModel model = CameraModel::load(model_path);
  EXPECT_EQ(model.intrinsics(), report["intrinsics"].get<std::vector<double>>());

  {
    std::ofstream script(dir_ / "check.py");
    script << kCheckScript;
  }
  ASSERT_EQ(shell(dir_, fmt::format("{} check.py camera.cameramodel camera.report.json > check.txt 2> check.log",
                                    kPython.string())),
            0)
      << test::read_text(dir_ / "check.log");
  const std::string text = test::read_text(dir_ / "check.txt");
  EXPECT_EQ(numbers_after(text, "stored_equals_model"), std::vector<double>{1.0}) << text;
  EXPECT_EQ(numbers_after(text, "observations"), std::vector<double>{double(report["views_used"].get<int>())}) << text;
  // The stored inputs are the solve arpipe ran: mrcal's optimizer, started from them with the same
  // flags and outlier marks, finds itself at the optimum (measured: no change at all, 0.0).
  const auto change = numbers_after(text, "reoptimized_change");
  ASSERT_EQ(change.size(), 1u) << text;
  EXPECT_LT(change[0], 1e-9) << text;
  const auto rms = numbers_after(text, "reoptimized_rms");
  ASSERT_EQ(rms.size(), 1u) << text;
  EXPECT_NEAR(rms[0], report["rms_per_coordinate_px"].get<double>(), 1e-9) << text;

  // The issue's bound: mrcal.projection_uncertainty on the written model agrees with the report's
  // grid within 10 %. Both evaluate mrcal's formula (uncertainty.org) on the same state and noise
  // estimate, so they should agree to rounding; measured 1e-10 relative for both lens models. The
  // 10 % is the issue's: enough slack for mrcal's noise estimate and for later mrcal versions,
  // far below what a wrong input (a missing outlier mark, a wrong flag) changes.
  const auto& grid = report["projection_uncertainty_grid"];
  const auto ours = grid["worst_direction_stdev_px"].get<std::vector<double>>();
  const auto theirs = numbers_after(text, "uncertainty");
  ASSERT_EQ(theirs.size(), ours.size()) << text;
  ASSERT_EQ(ours.size(), size_t(grid["cols"].get<int>() * grid["rows"].get<int>()));
  double worst = 0;
  for (size_t i = 0; i < ours.size(); ++i) {
    const double ratio = ours[i] / theirs[i];
    worst = std::max(worst, std::abs(ratio - 1.0));
    EXPECT_NEAR(ratio, 1.0, 0.10) << "grid point " << i << " (" << grid["pixels"][i][0] << ", " << grid["pixels"][i][1]
                                  << "): arpipe " << ours[i] << " px, mrcal " << theirs[i] << " px";
  }
  RecordProperty("worst_relative_difference_to_mrcal", fmt::format("{:.3g}", worst));

  // The tools, headless: plots written to SVG files, no display.
  ASSERT_EQ(shell(dir_, "env -u DISPLAY mrcal-show-projection-uncertainty --hardcopy uncertainty.svg "
                        "camera.cameramodel > uncertainty.log 2>&1"),
            0)
      << test::read_text(dir_ / "uncertainty.log");
  EXPECT_GT(fs::file_size(dir_ / "uncertainty.svg"), 1000u);
  // The worst-fitting view; its image path is a recording frame, not a file, so mrcal warns and
  // plots the residuals without the image.
  ASSERT_EQ(shell(dir_, "env -u DISPLAY mrcal-show-residuals-board-observation --from-worst --hardcopy residuals.svg "
                        "camera.cameramodel 0 > residuals.log 2>&1"),
            0)
      << test::read_text(dir_ / "residuals.log");
  EXPECT_GT(fs::file_size(dir_ / "residuals.svg"), 1000u);

  // mrcal-cull-corners reads no model: it filters a corners file. Its whole-view mode reads arpipe's
  // camera.corners.vnl (weights) as it is; half of the 60 views must come out, every kept corner
  // where it was.
  ASSERT_EQ(shell(dir_, "mrcal-cull-corners --cull-random-observations-ratio 0.5 --object-width-n 13 "
                        "--object-height-n 9 < camera.corners.vnl > culled.vnl 2> cull.log"),
            0)
      << test::read_text(dir_ / "cull.log");
  std::map<std::string, std::pair<std::string, std::string>> input;  // "name index" -> x, y
  std::map<std::string, int> seen_in_input;
  {
    std::istringstream lines(test::read_text(dir_ / "camera.corners.vnl"));
    for (std::string line; std::getline(lines, line);) {
      if (line.empty() || line[0] == '#') continue;
      std::istringstream words(line);
      std::string name, x, y;
      words >> name >> x >> y;
      input[name + " " + std::to_string(seen_in_input[name]++)] = {x, y};
    }
  }
  std::map<std::string, int> seen_in_output;
  int moved = 0;
  {
    std::istringstream lines(test::read_text(dir_ / "culled.vnl"));
    for (std::string line; std::getline(lines, line);) {
      if (line.empty() || line[0] == '#') continue;
      std::istringstream words(line);
      std::string name, x, y;
      words >> name >> x >> y;
      const auto it = input.find(name + " " + std::to_string(seen_in_output[name]++));
      if (it == input.end()) {
        ++moved;
        continue;
      }
      if (x == "-" || it->second.first == "-") {
        moved += (x == "-") != (it->second.first == "-");
        continue;
      }
      // mrcal prints Python's repr of the parsed double; compare the values.
      if (std::abs(std::stod(x) - std::stod(it->second.first)) > 1e-9 ||
          std::abs(std::stod(y) - std::stod(it->second.second)) > 1e-9)
        ++moved;
    }
  }
  EXPECT_EQ(seen_in_input.size(), 60u);
  EXPECT_EQ(seen_in_output.size(), 30u);
  for (const auto& [name, count] : seen_in_output) EXPECT_EQ(count, 13 * 9) << name;
  EXPECT_EQ(moved, 0);
}

INSTANTIATE_TEST_SUITE_P(LensModels, ArpipeCalibMrcalTools,
                         ::testing::Values("OPENCV8", "SPLINED_STEREOGRAPHIC"),
                         [](const auto& info) { return info.param; });

}  // namespace
