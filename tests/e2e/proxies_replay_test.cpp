// End-to-end: configs/proxies.toml through the real arpiped on the proxies capture (a real box and
// cylinder in front of a virtual cube, configs/sim/proxies.toml): every frame tracked and drawn,
// and each results line says how much of the cube the proxies hid and by which, against the
// simulator's visible coverage of it over the area of its whole outline.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "capture/recording/recording_reader.h"
#include "capture/sim/ground_truth_coverage.h"
#include "core/geometry/se3.h"
#include "tests/e2e/child_process.h"

namespace fs = std::filesystem;
using namespace arpipe;

namespace {

const fs::path kCapture = fs::path(ARPIPE_BINARY_DIR) / "proxies-capture";
const fs::path kConfig = fs::path(ARPIPE_SOURCE_DIR) / "configs/proxies.toml";

std::vector<nlohmann::json> run_proxies_replay() {
  const fs::path out = fs::path(ARPIPE_BINARY_DIR) / "e2e-out" / ("proxies-" + std::to_string(getpid()));
  fs::remove_all(out);
  fs::create_directories(out);
  const std::vector<std::string> args{"--config", kConfig.string(), "--set", "source.path=\"" + kCapture.string() + "\"",
                                      "--set", "sinks.png.enabled=false", "--set",
                                      "sinks.results.path=\"" + (out / "results.jsonl").string() + "\""};
  std::string stderr_text;
  const int code = test::run_to_exit(test::build_program("arpiped"), args, out / "logs", &stderr_text);
  EXPECT_EQ(code, 0) << stderr_text;
  std::vector<nlohmann::json> lines;
  std::ifstream in(out / "results.jsonl");
  for (std::string line; std::getline(in, line);) lines.push_back(nlohmann::json::parse(line));
  fs::remove_all(out);
  return lines;
}

// The area of the cube's whole outline (nothing in front) at the frame's middle: the convex hull
// of its 8 corners projected through the lens (its edges bend by well under a pixel here).
double outline_area_px(const CameraModel& camera, const SE3& T_cam_world) {
  const SE3 T_world_cube = SE3::from_rt({0, 0, 15 * M_PI / 180}, {0.175, 0.16, 0.0});
  const double h = 0.036;  // builtin:cube (6 cm) at scale 1.2
  std::vector<Vec2> points;
  for (int i = 0; i < 8; ++i)
    points.push_back(*camera.project(T_cam_world * (T_world_cube * Vec3{(i & 1) ? h : -h, (i & 2) ? h : -h, (i & 4) ? 2 * h : 0.0})));
  std::sort(points.begin(), points.end());
  const auto turn = [](const Vec2& o, const Vec2& a, const Vec2& b) {
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
  };
  std::vector<Vec2> hull(16);
  size_t k = 0;
  for (size_t i = 0; i < points.size(); ++i) {  // Andrew's monotone chain
    while (k >= 2 && turn(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  for (size_t i = points.size() - 1, t = k + 1; i-- > 0;) {
    while (k >= t && turn(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  double area = 0;
  for (size_t i = 0; i + 1 < k; ++i) area += hull[i][0] * hull[i + 1][1] - hull[i + 1][0] * hull[i][1];
  return std::abs(area) / 2;
}

TEST(ProxiesReplay, EveryFrameSaysHowMuchOfTheCubeIsHiddenAndByWhich) {
  ASSERT_TRUE(fs::exists(kCapture / "recording.json")) << "the build simulates it (proxies_capture)";
  const std::vector<nlohmann::json> results = run_proxies_replay();
  RecordingReader reader(kCapture);
  ASSERT_EQ(results.size(), reader.frame_count());
  for (size_t i = 0; i < results.size(); ++i) {
    const nlohmann::json& frame = results[i];
    ASSERT_TRUE(frame["virtual_layer_drawn"].get<bool>()) << frame.dump();
    ASSERT_TRUE(frame.contains("objects")) << frame.dump();
    const nlohmann::json& cube = frame["objects"][0];
    EXPECT_TRUE(cube["present"].get<bool>());
    EXPECT_TRUE(cube["in_view"].get<bool>());
    // The truth: what the simulator's coverage leaves of the whole outline's area.
    const sim::CoverageImage coverage = sim::read_coverage_frame(kCapture, i);
    double visible = 0;
    for (float c : coverage.coverage) visible += c;
    const double truth = 1 - visible / outline_area_px(reader.camera_model(), reader.ground_truth()[i].T_cam_world_mid);
    const double hidden = cube["hidden"].get<double>();
    // The tracked pose (about a millimetre off) and the report's 24 x 24 ray grid: within 0.05.
    EXPECT_NEAR(hidden, truth, 0.05) << "frame " << i;
    ASSERT_TRUE(cube["hidden_by"].contains("cylinder")) << cube.dump();
    double by_all = 0;
    for (const auto& [name, share] : cube["hidden_by"].items()) by_all += share.get<double>();
    EXPECT_NEAR(by_all, hidden, 1e-9);
  }
}

}  // namespace
