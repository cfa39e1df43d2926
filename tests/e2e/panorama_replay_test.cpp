// End-to-end: the hybrid example as a user runs it. `arpipe simulate --png` makes the panorama of
// configs/sim/proxies-panorama.toml, and arpiped runs configs/panorama.toml on it: every frame is
// composited from the pose the sweep gives (none tracked, none blurred), the pose in each results
// line is the configured sweep's, and the proxies report hiding part of the cube; with the still as
// the light, each frame's ambient light is the still's SH. Bad panorama
// files stop the daemon at setup with the file named.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <opencv2/imgcodecs.hpp>

#include "capture/panorama/equirect_image.h"
#include "capture/panorama/panorama_light.h"
#include "capture/panorama/panorama_source.h"
#include "capture/panorama/panorama_video.h"
#include "core/environment/hdr_environment.h"
#include "core/config/config.h"
#include "tests/e2e/child_process.h"

namespace fs = std::filesystem;
using namespace arpipe;

namespace {

const fs::path kConfig = fs::path(ARPIPE_SOURCE_DIR) / "configs/panorama.toml";
const fs::path kScene = fs::path(ARPIPE_SOURCE_DIR) / "configs/sim/proxies-panorama.toml";

fs::path out_dir(const std::string& name) {
  const fs::path dir = fs::path(ARPIPE_BINARY_DIR) / "e2e-out" / (name + "-" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

TEST(PanoramaReplay, TheHybridExampleRunsFromTheSimulatedStill) {
  const fs::path out = out_dir("panorama");
  std::string stderr_text;
  ASSERT_EQ(test::run_to_exit(test::build_program("arpipe"),
                              {"simulate", "--scene", kScene.string(), "--out", (out / "still").string(), "--png",
                               "--export-glb", (out / "world.glb").string()},
                              out / "logs-simulate", &stderr_text),
            0)
      << stderr_text;
  const fs::path still = out / "still" / "frame_000000.png";
  ASSERT_TRUE(fs::exists(still));
  constexpr int kFrames = 6;
  const std::vector<std::string> overrides{"source.panorama.file=\"" + still.string() + "\"",
                                           "source.panorama.view.frames=" + std::to_string(kFrames),
                                           "sinks.png.dir=\"" + (out / "png").string() + "\"",
                                           "sinks.results.path=\"" + (out / "results.jsonl").string() + "\""};
  std::vector<std::string> args{"--config", kConfig.string()};
  for (const std::string& o : overrides) args.insert(args.end(), {"--set", o});
  ASSERT_EQ(test::run_to_exit(test::build_program("arpiped"), args, out / "logs", &stderr_text), 0) << stderr_text;

  const Config config = load_config(kConfig, overrides);
  std::ifstream in(out / "results.jsonl");
  int lines = 0;
  for (std::string line; std::getline(in, line); ++lines) {
    const nlohmann::json frame = nlohmann::json::parse(line);
    ASSERT_TRUE(frame["virtual_layer_drawn"].get<bool>()) << line;
    EXPECT_EQ(frame["skipped"]["track"], "pose given by the source") << line;
    EXPECT_EQ(frame["blur"]["method"], "off") << line;
    // The pose is the sweep's at index / fps.
    const SE3 expected = panorama_view_pose(config.source.panorama.viewpoint(0), panorama_view_rotation_at(config.source.panorama, lines / config.source.panorama.view.fps));
    const SE3 reported = SE3::from_rt({frame["T_cam_world"]["r"][0], frame["T_cam_world"]["r"][1], frame["T_cam_world"]["r"][2]},
                                      {frame["T_cam_world"]["t"][0], frame["T_cam_world"]["t"][1], frame["T_cam_world"]["t"][2]});
    const SE3 difference = expected.inverse() * reported;
    EXPECT_LT(norm(difference.rotation_vector()), 1e-9) << line;
    EXPECT_LT(norm(difference.translation()), 1e-9) << line;
    // The cylinder stands in front of the cube's left half from this viewpoint.
    const nlohmann::json& cube = frame["objects"][0];
    EXPECT_TRUE(cube["in_view"].get<bool>()) << line;
    EXPECT_GT(cube["hidden_by"]["cylinder"].get<double>(), 0.2) << line;
    EXPECT_TRUE(fs::exists(out / "png" / fmt::format("frame_{:06d}.png", lines))) << lines;
  }
  EXPECT_EQ(lines, kFrames);

  // The same still as the light (light.source = "panorama"): each frame's ambient is the still's SH,
  // the direct light the config's.
  std::vector<std::string> lit_overrides = overrides;
  lit_overrides.insert(lit_overrides.end(), {"light.source=\"panorama\"", "source.panorama.view.frames=2",
                                             "sinks.results.path=\"" + (out / "lit.jsonl").string() + "\""});
  args = {"--config", kConfig.string()};
  for (const std::string& o : lit_overrides) args.insert(args.end(), {"--set", o});
  ASSERT_EQ(test::run_to_exit(test::build_program("arpiped"), args, out / "logs-lit", &stderr_text), 0) << stderr_text;
  const EquirectImage image = EquirectImage::load(still, 1.0);
  const ShRgb9 expected_sh = PanoramaLight(image.width(), image.height(), default_world_from_probe(config.source.panorama.yaw_rad)).project(image);
  std::ifstream lit(out / "lit.jsonl");
  int lit_lines = 0;
  for (std::string line; std::getline(lit, line); ++lit_lines) {
    const nlohmann::json light = nlohmann::json::parse(line)["light"];
    EXPECT_EQ(light["source"], "panorama") << line;
    EXPECT_EQ(light["state"], "estimated") << line;
    for (size_t i = 0; i < 9; ++i)
      for (size_t k = 0; k < 3; ++k) EXPECT_NEAR(light["ambient_sh"][i][k].get<double>(), expected_sh[i][k], 1e-9) << i << " " << k;
    ASSERT_EQ(light["lights"].size(), 1u) << line;
    for (size_t k = 0; k < 3; ++k)
      EXPECT_NEAR(light["lights"][0]["direction_world"][k].get<double>(), config.render.light_direction[k], 1e-12);
  }
  EXPECT_EQ(lit_lines, 2);

  // The scene's own lights, exported by the simulator with its real objects: the sun the config's
  // render.light_direction copies (to 4 decimals) comes back as the frame's light.
  ASSERT_TRUE(fs::exists(out / "world.glb"));
  std::vector<std::string> exported_overrides = overrides;
  exported_overrides.insert(exported_overrides.end(),
                            {"light.source=\"panorama\"", "source.panorama.view.frames=1",
                             "light.panorama.lights_file=\"" + (out / "world.glb").string() + "\"",
                             "sinks.results.path=\"" + (out / "exported.jsonl").string() + "\""});
  args = {"--config", kConfig.string()};
  for (const std::string& o : exported_overrides) args.insert(args.end(), {"--set", o});
  ASSERT_EQ(test::run_to_exit(test::build_program("arpiped"), args, out / "logs-exported", &stderr_text), 0) << stderr_text;
  std::ifstream exported(out / "exported.jsonl");
  std::string line;
  ASSERT_TRUE(std::getline(exported, line));
  const nlohmann::json exported_light = nlohmann::json::parse(line)["light"];
  ASSERT_EQ(exported_light["lights"].size(), 1u) << line;
  for (size_t k = 0; k < 3; ++k)
    EXPECT_NEAR(exported_light["lights"][0]["direction_world"][k].get<double>(), config.render.light_direction[k], 1e-4) << line;
  fs::remove_all(out);
}

TEST(PanoramaReplay, AStereoStillGivesBothEyesPackedOrAsFramesOfTheirOwn) {
  // A top/bottom pair whose left eye is red and right eye blue, through the hybrid example (the
  // layout "auto": told by the 1:1 shape).
  const fs::path out = out_dir("panorama-stereo");
  const fs::path still = out / "pair.png";
  ASSERT_EQ(std::system(fmt::format("ffmpeg -nostdin -v error -y -f lavfi -i 'color=c=red:s=512x256[a];color=c=blue:s=512x256[b];"
                                    "[a][b]vstack' -frames:v 1 '{}'", still.string()).c_str()),
            0);
  constexpr int kSteps = 3, kWidth = 320, kHeight = 180;
  const auto run = [&](const std::string& packing, const std::string& name) {
    const std::vector<std::string> overrides{"source.panorama.file=\"" + still.string() + "\"",
                                             "source.panorama.view.stereo_output=\"" + packing + "\"",
                                             "source.panorama.view.frames=" + std::to_string(kSteps),
                                             fmt::format("source.panorama.view.width={}", kWidth),
                                             fmt::format("source.panorama.view.height={}", kHeight),
                                             "sinks.png.dir=\"" + (out / name).string() + "\"",
                                             "sinks.results.path=\"" + (out / (name + ".jsonl")).string() + "\""};
    std::vector<std::string> args{"--config", kConfig.string()};
    for (const std::string& o : overrides) args.insert(args.end(), {"--set", o});
    std::string stderr_text;
    EXPECT_EQ(test::run_to_exit(test::build_program("arpiped"), args, out / ("logs-" + name), &stderr_text), 0) << stderr_text;
    std::vector<nlohmann::json> lines;
    std::ifstream in(out / (name + ".jsonl"));
    for (std::string line; std::getline(in, line);) lines.push_back(nlohmann::json::parse(line));
    return lines;
  };
  // Packed top/bottom: a frame a time step, twice as high, red above blue.
  const std::vector<nlohmann::json> packed = run("tb", "tb");
  ASSERT_EQ(packed.size(), size_t(kSteps));
  for (size_t k = 0; k < packed.size(); ++k) {
    EXPECT_EQ(packed[k]["eye"], "pair");
    EXPECT_TRUE(packed[k]["virtual_layer_drawn"].get<bool>());
    const cv::Mat png = cv::imread((out / "tb" / fmt::format("frame_{:06d}.png", packed[k]["index"].get<int>())).string());
    ASSERT_EQ(png.cols, kWidth);
    ASSERT_EQ(png.rows, 2 * kHeight);
    const cv::Vec3b top = png.at<cv::Vec3b>(2, 2), bottom = png.at<cv::Vec3b>(kHeight + 2, 2);  // BGR, a corner of sky
    EXPECT_TRUE(top[2] > 200 && top[0] < 60) << "the left eye's picture is not on top";
    EXPECT_TRUE(bottom[0] > 200 && bottom[2] < 60) << "the right eye's picture is not below";
  }
  // Side by side.
  const std::vector<nlohmann::json> beside = run("lr", "lr");
  ASSERT_EQ(beside.size(), size_t(kSteps));
  const cv::Mat png = cv::imread((out / "lr" / fmt::format("frame_{:06d}.png", beside[0]["index"].get<int>())).string());
  EXPECT_EQ(png.cols, 2 * kWidth);
  EXPECT_EQ(png.rows, kHeight);
  // Each eye its own frame: left then right, the same time.
  const std::vector<nlohmann::json> frames = run("frames", "frames");
  ASSERT_EQ(frames.size(), size_t(2 * kSteps));
  for (size_t k = 0; k < frames.size(); ++k) {
    EXPECT_EQ(frames[k]["eye"], k % 2 == 0 ? "left" : "right");
    EXPECT_EQ(frames[k]["exposure_start_ns"], frames[k - k % 2]["exposure_start_ns"]);
  }
  fs::remove_all(out);
}

TEST(PanoramaReplay, SimulateWritesAStereoVideoTheSourceReads) {
  // A 128 x 64 omnidirectional-stereo pair, top/bottom, 3 frames, as an MP4 with its metadata.
  const fs::path out = out_dir("panorama-sim-video");
  std::ofstream(out / "scene.toml") << R"([camera]
lensmodel = "LENSMODEL_LONLAT"
intrinsics = [20.371832715762604, 20.371832715762604, 63.5, 31.5]
width = 128
height = 64
pixel_format = "RGB24"
[camera.stereo]
layout = "tb"
[camera.sensor]
noise = false
[render]
samples_per_pixel = 1
frames = 3
[environment]
radiance = [0.3, 0.5, 0.8]
[[object]]
shape = "sphere"
radius_m = 0.2
position = [0.0, 1.0, 0.0]
albedo = [0.9, 0.2, 0.1]
)";
  std::string stderr_text;
  ASSERT_EQ(test::run_to_exit(test::build_program("arpipe"),
                              {"simulate", "--scene", (out / "scene.toml").string(), "--out", (out / "rec").string(),
                               "--video", (out / "pair.mp4").string()},
                              out / "logs", &stderr_text),
            0)
      << stderr_text;
  PanoramaVideo video(out / "pair.mp4");
  EXPECT_EQ(video.layout(), PanoramaLayout::EquirectTopBottom);  // from its metadata
  PanoramaVideoFrame frame;
  int frames = 0;
  while (video.next(frame)) {
    EXPECT_EQ(frame.width, 128);
    EXPECT_EQ(frame.height, 128);
    EXPECT_EQ(frame.index, frames);
    ++frames;
  }
  EXPECT_EQ(frames, 3);
  fs::remove_all(out);
}

TEST(PanoramaReplay, BadStillsStopTheDaemonAtSetupNamingTheFile) {
  const fs::path out = out_dir("panorama-bad");
  std::ofstream(out / "not-a-panorama.png") << "text, not an image\n";
  for (const fs::path& file : {out / "not-a-panorama.png", out / "missing.png"}) {
    std::string stderr_text;
    const int code = test::run_to_exit(
        test::build_program("arpiped"),
        {"--config", kConfig.string(), "--set", "source.panorama.file=\"" + file.string() + "\"", "--set",
         "sinks.png.dir=\"" + (out / "png").string() + "\"", "--set", "sinks.results.path=\"" + (out / "r.jsonl").string() + "\""},
        out / "logs", &stderr_text);
    EXPECT_NE(code, 0);
    EXPECT_NE(stderr_text.find(file.string()), std::string::npos) << stderr_text;
  }
  fs::remove_all(out);
}

}  // namespace
