// `arpipe calib` as a person runs it, on the simulator's calib-board capture whose lens is known
// exactly (configs/sim/calib-board.toml: a wide LENSMODEL_OPENCV8 lens): the solved model must
// match the true one to the bounds, and bad input must get advice, not a crash.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "capture/recording/recording_reader.h"
#include "core/geometry/camera_model.h"
#include "core/image/pixel_convert.h"
#include "tests/e2e/child_process.h"

namespace fs = std::filesystem;
using namespace arpipe;

namespace {

const fs::path kCapture = fs::path(ARPIPE_BINARY_DIR) / "calib-capture";
const fs::path kBoard = fs::path(ARPIPE_SOURCE_DIR) / "configs/boards/chessboard-10x14-20mm.toml";

class ArpipeCalib : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(ARPIPE_BINARY_DIR) / "e2e-out" / ::testing::UnitTest::GetInstance()->current_test_info()->name();
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  int run(const std::vector<std::string>& args, std::string* out = nullptr, std::string* err = nullptr) {
    test::ChildProcess child(test::build_program("arpipe"), args, dir_ / "logs");
    const int status = child.wait(std::chrono::seconds(300));
    if (out) *out = child.stdout_text();
    if (err) *err = child.stderr_text();
    if (status == -1 || !WIFEXITED(status)) return -1;  // a timeout or a crash
    return WEXITSTATUS(status);
  }
  // Frames of the capture as grey PNG files, optionally shrunk, for the --images path.
  std::vector<fs::path> write_pngs(const std::vector<size_t>& frames, const std::string& prefix, double scale = 1.0) {
    RecordingReader reader(kCapture);
    std::vector<fs::path> paths;
    for (size_t i : frames) {
      Frame frame;
      reader.read(i, frame);
      std::vector<uint8_t> grey;
      to_grey(frame, grey);
      cv::Mat image(frame.height, frame.width, CV_8UC1, grey.data());
      cv::Mat out = image;
      if (scale != 1.0) cv::resize(image, out, cv::Size(), scale, scale, cv::INTER_AREA);
      paths.push_back(dir_ / fmt::format("{}{:03d}.png", prefix, i));
      EXPECT_TRUE(cv::imwrite(paths.back().string(), out));
    }
    return paths;
  }
  fs::path dir_;
};

// Largest distance between where the two models put the same ray, over pixels every `step` px of
// the true model's image (restricted by `keep`). The intrinsics of a monocular calibration are
// absolute (the camera frame is the reference), so no transform is fitted between the models.
template <typename Keep>
double max_projection_difference(const CameraModel& truth, const CameraModel& solved, int step, Keep keep) {
  double worst = 0;
  for (int v = 0; v < truth.height(); v += step)
    for (int u = 0; u < truth.width(); u += step) {
      const Vec2 q{double(u), double(v)};
      if (!keep(q)) continue;
      const auto ray = truth.unproject(q);
      if (!ray) return INFINITY;
      const auto back = solved.project(*ray);
      if (!back) return INFINITY;
      worst = std::max(worst, std::hypot((*back)[0] - q[0], (*back)[1] - q[1]));
    }
  return worst;
}

TEST_F(ArpipeCalib, RecoversTheSimulatedWideLensWithOpencv8) {
  const fs::path model_path = dir_ / "camera.cameramodel";
  std::string out, err;
  ASSERT_EQ(run({"calib", "--recording", kCapture.string(), "--board", kBoard.string(), "--out", model_path.string()},
                &out, &err),
            0)
      << err;
  const CameraModel truth = RecordingReader(kCapture).camera_model();
  const CameraModel solved = CameraModel::load(model_path);
  ASSERT_EQ(solved.lensmodel(), "LENSMODEL_OPENCV8");
  ASSERT_EQ(solved.width(), truth.width());
  // The bounds: fx, fy within 0.5 %, cx, cy within 1 px, projection within 0.1 px everywhere.
  EXPECT_NEAR(solved.fx() / truth.fx(), 1.0, 0.005);
  EXPECT_NEAR(solved.fy() / truth.fy(), 1.0, 0.005);
  EXPECT_NEAR(solved.cx(), truth.cx(), 1.0);
  EXPECT_NEAR(solved.cy(), truth.cy(), 1.0);
  const double difference = max_projection_difference(truth, solved, 8, [](const Vec2&) { return true; });
  EXPECT_LT(difference, 0.1) << out;
  RecordProperty("max_projection_difference_px", std::to_string(difference));

  // What comes beside the model: a report in both forms, the picture and the corners.
  const auto report = nlohmann::json::parse(test::read_text(dir_ / "camera.report.json"));
  EXPECT_EQ(report["views_used"].get<int>(), 30);
  EXPECT_EQ(report["images_total"].get<int>(), 30);
  EXPECT_LT(report["rms_per_point_px"].get<double>(), 0.5);
  EXPECT_EQ(report["projection_uncertainty_at_infinity"].size(), 5u);
  EXPECT_NE(test::read_text(dir_ / "camera.report.txt").find("RMS"), std::string::npos);
  const cv::Mat picture = cv::imread((dir_ / "camera.residuals.png").string());
  EXPECT_EQ(picture.cols, truth.width());
  std::ifstream vnl(dir_ / "camera.corners.vnl");
  int rows = 0;
  for (std::string line; std::getline(vnl, line);) rows += !line.empty() && line[0] != '#';
  EXPECT_EQ(rows, 30 * 9 * 13);
}

TEST_F(ArpipeCalib, RecoversTheLensWithTheSplinedModelWhereObserved) {
  const fs::path model_path = dir_ / "splined.cameramodel";
  std::string out, err;
  ASSERT_EQ(run({"calib", "--recording", kCapture.string(), "--board", kBoard.string(), "--lensmodel",
                 "SPLINED_STEREOGRAPHIC", "--out", model_path.string()},
                &out, &err),
            0)
      << err;
  const CameraModel truth = RecordingReader(kCapture).camera_model();
  const CameraModel solved = CameraModel::load(model_path);
  ASSERT_EQ(solved.lensmodel().rfind("LENSMODEL_SPLINED_STEREOGRAPHIC", 0), 0u) << solved.lensmodel();
  // "Where the observations cover the image": cells of the report's coverage grid that hold points.
  const auto report = nlohmann::json::parse(test::read_text(dir_ / "splined.report.json"));
  const int cols = report["coverage"]["cols"].get<int>();
  const int rows = report["coverage"]["rows"].get<int>();
  const auto points = report["coverage"]["points"].get<std::vector<int>>();
  const auto observed = [&](const Vec2& q) {
    const int cx = std::min(cols - 1, int(q[0] * cols / truth.width()));
    const int cy = std::min(rows - 1, int(q[1] * rows / truth.height()));
    return points[size_t(cy * cols + cx)] > 0;
  };
  const double difference = max_projection_difference(truth, solved, 8, observed);
  EXPECT_LT(difference, 0.1) << out;
  RecordProperty("max_projection_difference_px", std::to_string(difference));
}

TEST_F(ArpipeCalib, TooFewImagesGetAdvice) {
  write_pngs({0, 1, 2}, "view");
  std::string out, err;
  EXPECT_EQ(run({"calib", "--images", (dir_ / "view*.png").string(), "--board", kBoard.string(), "--out",
                 (dir_ / "camera.cameramodel").string()},
                &out, &err),
            1);
  EXPECT_NE(err.find("views"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(dir_ / "camera.cameramodel"));
}

TEST_F(ArpipeCalib, ABoardFileThatDoesNotMatchTheImagesNamesWhatTheyShow) {
  // The usual mistake: squares counted (10 x 14) instead of inner corners (9 x 13).
  const fs::path board = dir_ / "squares.toml";
  std::ofstream(board) << "kind = \"chessboard\"\ninner_corners = [10, 14]\nsquare_m = 0.02\n";
  write_pngs({0, 1, 2, 3}, "view");
  std::string out, err;
  EXPECT_EQ(run({"calib", "--images", (dir_ / "view*.png").string(), "--board", board.string(), "--out",
                 (dir_ / "camera.cameramodel").string()},
                &out, &err),
            1);
  EXPECT_NE(err.find("found in none of the 4 images"), std::string::npos) << err;
  EXPECT_NE(err.find("inner_corners = [9, 13]"), std::string::npos) << err;
}

TEST_F(ArpipeCalib, MixedImageSizesAreRefusedByName) {
  write_pngs({0, 1, 2, 3}, "a");
  write_pngs({4}, "b", 0.5);
  std::string out, err;
  EXPECT_EQ(run({"calib", "--images", (dir_ / "*.png").string(), "--board", kBoard.string(), "--out",
                 (dir_ / "camera.cameramodel").string()},
                &out, &err),
            1);
  EXPECT_NE(err.find("b004.png is 320x240 but"), std::string::npos) << err;
}

TEST_F(ArpipeCalib, NoImagesAndBadArgumentsAreClear) {
  std::string out, err;
  EXPECT_EQ(run({"calib", "--images", (dir_ / "none*.png").string(), "--board", kBoard.string(), "--out",
                 (dir_ / "c.cameramodel").string()},
                &out, &err),
            1);
  EXPECT_NE(err.find("none*.png"), std::string::npos) << err;
  EXPECT_EQ(run({"calib", "--board", kBoard.string()}, &out, &err), 2);
  EXPECT_NE(err.find("--images"), std::string::npos) << err;
  EXPECT_EQ(run({"calib", "--recording", kCapture.string(), "--board", (dir_ / "missing.toml").string(), "--out",
                 (dir_ / "c.cameramodel").string()},
                &out, &err),
            1);
  EXPECT_NE(err.find("missing.toml"), std::string::npos) << err;
}

}  // namespace
