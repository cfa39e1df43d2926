// The `arpipe` utility as a person runs it: inspect, replay, simulate, config; bad input exits 2
// with a message naming the file, never a crash.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <tuple>
#include <vector>

#include "capture/recording/recording_reader.h"
#include "capture/recording/recording_writer.h"
#include "core/image/radiance_hdr.h"
#include "core/scene/gltf_loader.h"
#include "tests/e2e/child_process.h"

namespace fs = std::filesystem;
using namespace arpipe;

namespace {

const fs::path kCapture = fs::path(ARPIPE_BINARY_DIR) / "default-capture";

class ArpipeCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(ARPIPE_BINARY_DIR) / "e2e-out" / ::testing::UnitTest::GetInstance()->current_test_info()->name();
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  int run(const std::vector<std::string>& args, std::string* out = nullptr, std::string* err = nullptr,
          std::chrono::seconds timeout = std::chrono::seconds(120)) {
    test::ChildProcess child(test::build_program("arpipe"), args, dir_ / "logs");
    const int status = child.wait(timeout);
    if (out) *out = child.stdout_text();
    if (err) *err = child.stderr_text();
    if (status == -1 || !WIFEXITED(status)) return -1;  // a timeout or a crash
    return WEXITSTATUS(status);
  }
  // A build with -DARPIPE_BUILD_BENCH=OFF (CI's sanitizer tree) has no benchmarks to run.
  bool benchmarks_built() {
    std::string out;
    return run({"bench", "--help"}, &out) == 0 && out.find("blur") != std::string::npos;
  }
  fs::path dir_;
};

TEST_F(ArpipeCli, InspectSummarisesTheDefaultCapture) {
  std::string out, err;
  ASSERT_EQ(run({"inspect", kCapture.string()}, &out, &err), 0) << err;
  RecordingReader reader(kCapture);  // the numbers the summary must show
  EXPECT_NE(out.find("YUYV 640x480"), std::string::npos) << out;
  EXPECT_NE(out.find("frames       " + std::to_string(reader.frame_count())), std::string::npos) << out;
  EXPECT_NE(out.find("0 dropped"), std::string::npos) << out;
  EXPECT_NE(out.find("30.00 frames/s"), std::string::npos) << out;  // the generator's rate
  EXPECT_NE(out.find("ground truth yes"), std::string::npos) << out;
}

TEST_F(ArpipeCli, InspectCountsSequenceGaps) {
  // Sequence numbers 0, 1, 2, 5, 6: a driver lost 3 and 4.
  const fs::path capture = dir_ / "gappy";
  {
    RecordingInfo info;
    info.pixel_format = PixelFormat::GREY;
    info.width = 8;
    info.height = 6;
    info.source = "test";
    RecordingWriter writer(capture, info, CameraModel::pinhole(10, 10, 3.5, 2.5, 8, 6));
    for (uint64_t sequence : {0, 1, 2, 5, 6}) {
      Frame frame = Frame::allocate(PixelFormat::GREY, 8, 6);
      frame.meta.sequence = sequence;
      frame.meta.exposure_start_ns = int64_t(sequence) * 33'333'333;
      frame.meta.frame_duration_ns = 33'333'333;
      writer.append(frame);
    }
  }
  std::string out, err;
  ASSERT_EQ(run({"inspect", capture.string()}, &out, &err), 0) << err;
  EXPECT_NE(out.find("0 .. 6, 2 dropped"), std::string::npos) << out;
}

TEST_F(ArpipeCli, InspectOfAMissingRecordingNamesIt) {
  std::string err;
  EXPECT_EQ(run({"inspect", (dir_ / "nothing-here").string()}, nullptr, &err), 2);
  EXPECT_NE(err.find("nothing-here"), std::string::npos) << err;
}

// A scene from configs/sim rendered small and fast, then replayed: every frame comes out, the tag
// is tracked, and the recording carries its ground truth and a copy of the scene.
TEST_F(ArpipeCli, SimulateThenReplay) {
  const fs::path capture = dir_ / "sim";
  const fs::path scene = fs::path(ARPIPE_SOURCE_DIR) / "configs" / "sim" / "tag-static.toml";
  std::string err;
  ASSERT_EQ(run({"simulate", "--scene", scene.string(), "--out", capture.string(), "--frames", "3", "--samples", "1",
                 "--seed", "11"},
                nullptr, &err),
            0)
      << err;
  EXPECT_NE(err.find("3/3 frames"), std::string::npos) << err;  // the progress report
  RecordingReader reader(capture);
  EXPECT_EQ(reader.frame_count(), 3u);
  EXPECT_EQ(reader.ground_truth().size(), 3u);
  EXPECT_TRUE(fs::exists(capture / "scene.toml"));
  // Refuses to overwrite a recording.
  EXPECT_EQ(run({"simulate", "--scene", scene.string(), "--out", capture.string()}, nullptr, &err), 1);
  EXPECT_NE(err.find(capture.string()), std::string::npos) << err;

  // The cube the defaults drew before a config had to name its objects: without an object in the
  // scene there is nothing to track for.
  ASSERT_EQ(run({"replay", capture.string(), "--set", "sinks.png.enabled=false", "--set", "sinks.y4m.enabled=false",
                 "--set", "sinks.results.path=\"" + (dir_ / "r.jsonl").string() + "\"", "--set",
                 "render.objects=[{mesh=\"builtin:cube\"}]"},
                nullptr, &err),
            0)
      << err;
  std::ifstream results(dir_ / "r.jsonl");
  size_t lines = 0, tracking = 0;
  for (std::string line; std::getline(results, line);) {
    ++lines;
    if (line.find("\"track_state\":\"tracking\"") != std::string::npos) ++tracking;
  }
  EXPECT_EQ(lines, 3u);
  EXPECT_EQ(tracking, 3u);
}

TEST_F(ArpipeCli, ReplayRefusesAFallbackExposureLongerThanTheFrameInterval) {
  // The default capture runs at 30 fps: no exposure can last 50 ms. Refused before any frame, with
  // the file, the key and the source's interval; nothing is written.
  std::ofstream(dir_ / "long.toml") << "[motion]\ndefault_exposure_ms = 50\n[sinks.results]\npath = \""
                                    << (dir_ / "r.jsonl").string() << "\"\n";
  std::string err;
  EXPECT_EQ(run({"replay", kCapture.string(), "--config", (dir_ / "long.toml").string()}, nullptr, &err), 2);
  EXPECT_NE(err.find("long.toml"), std::string::npos) << err;
  EXPECT_NE(err.find("motion.default_exposure_ms = 50"), std::string::npos) << err;
  EXPECT_NE(err.find("frame interval"), std::string::npos) << err;
  EXPECT_NE(err.find("33.3"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(dir_ / "r.jsonl"));
  // 30 ms fits.
  std::ofstream(dir_ / "ok.toml") << "[motion]\ndefault_exposure_ms = 30\n[sinks.results]\npath = \""
                                  << (dir_ / "r.jsonl").string() << "\"\n[sinks.png]\nenabled = false\n[sinks.y4m]\nenabled = false\n";
  EXPECT_EQ(run({"replay", kCapture.string(), "--config", (dir_ / "ok.toml").string()}, nullptr, &err), 0) << err;
}

TEST_F(ArpipeCli, BenchBlurPrintsItsTableOnAShortCapture) {
  if (!benchmarks_built()) GTEST_SKIP() << "arpipe built without the benchmarks";
  // A 6-frame blur-bench capture at 1 sample per pixel and a 16-render reference: the command runs
  // end to end and prints a row per method; the numbers themselves are the bench's, not a test's.
  const fs::path capture = dir_ / "capture";
  const fs::path scene = fs::path(ARPIPE_SOURCE_DIR) / "configs" / "sim" / "blur-bench.toml";
  std::string out, err;
  ASSERT_EQ(run({"simulate", "--scene", scene.string(), "--out", capture.string(), "--frames", "6", "--samples", "1"},
                nullptr, &err),
            0)
      << err;
  ASSERT_EQ(run({"bench", "blur", "--capture", capture.string(), "--reference-samples", "16"}, &out, &err), 0) << err;
  for (const char* row : {"| accumulate 16 (reference) |", "| off auto |", "| intraframe-warp auto |", "| velocity auto |"})
    EXPECT_NE(out.find(row), std::string::npos) << row << "\n" << out;
  EXPECT_EQ(run({"bench", "blur", "--capture", (dir_ / "missing").string()}, nullptr, &err), 1);
  EXPECT_NE(err.find("missing"), std::string::npos) << err;
}

// The table row that starts with `label`, split at its bars (empty when none).
std::vector<std::string> table_row(const std::string& table, const std::string& label) {
  const size_t at = table.find("| " + label + " |");
  if (at == std::string::npos) return {};
  const std::string line = table.substr(at, table.find('\n', at) - at);
  std::vector<std::string> cells;
  size_t from = 1;
  for (size_t bar; (bar = line.find('|', from)) != std::string::npos; from = bar + 1) cells.push_back(line.substr(from, bar - from));
  return cells;
}

// Seed 003's protocol end to end on the courtyard, cut short (8 frames, 2 truth views, few rays):
// every input is made, every path runs, and the table holds what the issue asks of it. The bars
// that hold whatever the machine: the hybrid's picture is nearer the ray-traced truth than arpipe's
// own full 3D render (issue 23: "no larger error"), and the whole proxies' occlusion edges are
// within 1 px of the truth's. The speeds are the benchmark's, not a test's.
TEST_F(ArpipeCli, BenchHybridRunsTheSeedsProtocolAgainstTheTruth) {
  if (!benchmarks_built()) GTEST_SKIP() << "arpipe built without the benchmarks";
  const fs::path configs = fs::path(ARPIPE_SOURCE_DIR) / "configs";
  std::string out, err;
  // Two viewpoints, as the seed's protocol repeats at each: the config's, and one 0.7 m away.
  ASSERT_EQ(run({"bench", "hybrid", "--scene", (configs / "sim" / "courtyard.toml").string(), "--config",
                 (configs / "courtyard.toml").string(), "--work", (dir_ / "hybrid").string(), "--frames", "8",
                 "--truth-views", "2", "--still-samples", "4", "--video-frames", "2", "--video-samples", "1",
                 "--viewpoint", "0,0,1.6", "--viewpoint", "0.5,-0.5,1.6"},
                &out, &err, std::chrono::seconds(270)),  // 60 s alone; twice that beside the heaviest tests
            0)
      << err;
  EXPECT_NE(out.find("at (0.50, -0.50, 1.60)"), std::string::npos) << out;
  const size_t summary = out.find("All 2 viewpoints");
  ASSERT_NE(summary, std::string::npos) << out;
  EXPECT_EQ(table_row(out.substr(summary), "hybrid, still").size(), 5u) << out;  // path, proxies, 2 viewpoints, mean
  const std::string tables = out.substr(0, summary);  // each viewpoint's
  const std::vector<std::string> full = table_row(tables, "full 3D scene");
  ASSERT_EQ(full.size(), 8u) << out;
  int hybrid_rows = 0;
  for (const char* path : {"hybrid, video", "hybrid, still"})
    for (size_t at = tables.find(std::string("| ") + path + " |"); at != std::string::npos;
         at = tables.find(std::string("| ") + path + " |", at + 1)) {
      const std::vector<std::string> row = table_row(tables.substr(at), path);
      ASSERT_EQ(row.size(), 8u) << out;
      ++hybrid_rows;
      if (std::string(path) == "hybrid, still") {
        EXPECT_GT(std::stod(row[6]), std::stod(full[6])) << "PSNR\n" << out;
      }
      if (row[1].find("whole") != std::string::npos) {
        EXPECT_LE(std::stod(row[7]), 1.0) << "edge\n" << out;
      }
    }
  EXPECT_EQ(hybrid_rows, 2 * 4) << out;  // video and still, proxies whole and 10:1, at each viewpoint
  for (const char* viewpoint : {"viewpoint-0", "viewpoint-1"})
    for (const char* file : {"world.glb", "video.mp4", "still/frame_000000.png", "view-0-truth.png"})
      EXPECT_TRUE(fs::exists(dir_ / "hybrid" / viewpoint / file)) << viewpoint << "/" << file;
  // A config that is not a panorama's is refused by name.
  EXPECT_EQ(run({"bench", "hybrid", "--scene", (configs / "sim" / "courtyard.toml").string(), "--config",
                 (configs / "arpipe.toml").string(), "--work", (dir_ / "bad").string()},
                nullptr, &err),
            1);
  EXPECT_NE(err.find("source.type"), std::string::npos) << err;
  // A scene whose objects move is refused by the object's name (the benchmark's geometry stands still).
  EXPECT_EQ(run({"bench", "hybrid", "--scene", (configs / "sim" / "hybrid-animated.toml").string(), "--config",
                 (configs / "hybrid-animated.toml").string(), "--work", (dir_ / "moving").string()},
                nullptr, &err),
            1);
  EXPECT_NE(err.find("\"cart\" moves"), std::string::npos) << err;
  // A viewpoint that is not three numbers is a usage error naming the option.
  EXPECT_EQ(run({"bench", "hybrid", "--viewpoint", "1,2"}, nullptr, &err), 2);
  EXPECT_NE(err.find("--viewpoint"), std::string::npos) << err;
}

// A config that cannot be read is an error naming it (exit 1), not an uncaught exception.
TEST_F(ArpipeCli, BenchPipelineNamesAMissingConfig) {
  if (!benchmarks_built()) GTEST_SKIP() << "arpipe built without the benchmarks";
  std::string err;
  EXPECT_EQ(run({"bench", "pipeline", "--config", (dir_ / "missing.toml").string(), "--frames", "1"}, nullptr, &err),
            1);
  EXPECT_NE(err.find("missing.toml"), std::string::npos) << err;
}

TEST_F(ArpipeCli, SimulateNamesTheBadSceneFileAndKey) {
  std::ofstream(dir_ / "bad.toml") << "[camera]\nexposure_ms = 0\n";
  std::string err;
  EXPECT_EQ(run({"simulate", "--scene", (dir_ / "bad.toml").string(), "--out", (dir_ / "x").string()}, nullptr, &err),
            2);
  EXPECT_NE(err.find("bad.toml"), std::string::npos) << err;
  EXPECT_NE(err.find("exposure_ms"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(dir_ / "x"));
  EXPECT_EQ(run({"simulate", "--scene", (dir_ / "bad.toml").string(), "--out", (dir_ / "x").string(), "--samples",
                 "5"},
                nullptr, &err),
            2);
  EXPECT_NE(err.find("--samples"), std::string::npos) << err;
}

// --export-leave-out takes an object out of the exported proxies by name (the real ground, which
// the ground catcher stands for): the GLB holds the rest, 2 triangles fewer for the courtyard's
// paving; a name the scene lacks is an error naming it, before any frame. The GLB may go inside
// --out's folder before it exists (OPERATIONS.md's courtyard commands do).
TEST_F(ArpipeCli, SimulateExportLeavesOutTheNamedObject) {
  const fs::path scene = fs::path(ARPIPE_SOURCE_DIR) / "configs" / "sim" / "courtyard.toml";
  std::string err;
  const fs::path all_glb = dir_ / "all.glb", standing_glb = dir_ / "standing" / "world.glb";
  for (const auto& [glb, out, leave_out] : {std::tuple{all_glb, dir_ / "all", ""},
                                            std::tuple{standing_glb, dir_ / "standing", "paving"}}) {
    std::vector<std::string> args{"simulate", "--scene", scene.string(), "--out", out.string(),
                                  "--samples", "1", "--frames", "1", "--export-glb", glb.string()};
    if (*leave_out) args.insert(args.end(), {"--export-leave-out", leave_out});
    ASSERT_EQ(run(args, nullptr, &err), 0) << err;
  }
  const Mesh all = load_gltf_mesh(all_glb);
  const Mesh standing = load_gltf_mesh(standing_glb);
  EXPECT_EQ(all.triangle_count(), standing.triangle_count() + 2);  // the paving's rectangle
  EXPECT_EQ(all.parts.size(), standing.parts.size() + 1);
  EXPECT_EQ(run({"simulate", "--scene", scene.string(), "--out", (dir_ / "none").string(), "--export-glb",
                 (dir_ / "none.glb").string(), "--export-leave-out", "lawn"},
                nullptr, &err),
            1);
  EXPECT_NE(err.find("lawn"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(dir_ / "none"));
}

TEST_F(ArpipeCli, ConfigDefaultsAreAValidConfigAndCheckNamesErrors) {
  std::string out, err;
  ASSERT_EQ(run({"config", "--defaults"}, &out, &err), 0) << err;
  std::ofstream(dir_ / "defaults.toml") << out;
  EXPECT_EQ(run({"config", "--check", (dir_ / "defaults.toml").string()}, &out, &err), 0) << err;
  // config --check also opens the recording it names (relative to the working directory, which is
  // not the repository root here): check the shipped config with that path made absolute.
  std::string shipped = test::read_text(fs::path(ARPIPE_SOURCE_DIR) / "configs" / "arpipe.toml");
  shipped.replace(shipped.find("\"build/default-capture\""), 23, "\"" + kCapture.string() + "\"");
  std::ofstream(dir_ / "shipped.toml") << shipped;
  EXPECT_EQ(run({"config", "--check", (dir_ / "shipped.toml").string()}, &out, &err), 0) << err;
  std::ofstream(dir_ / "bad.toml") << "[render]\nmsaa_samples = 3\n";
  EXPECT_EQ(run({"config", "--check", (dir_ / "bad.toml").string()}, &out, &err), 2);
  EXPECT_NE(err.find("bad.toml"), std::string::npos) << err;
  EXPECT_NE(err.find("msaa_samples"), std::string::npos) << err;
}

TEST_F(ArpipeCli, UnknownCommandIsAUsageError) {
  std::string err;
  EXPECT_EQ(run({"frobnicate"}, nullptr, &err), 2);
  EXPECT_NE(err.find("frobnicate"), std::string::npos) << err;
  EXPECT_EQ(run({}, nullptr, &err), 2);  // no command at all
}

TEST_F(ArpipeCli, VersionAndHelpOfEveryCommand) {
  std::string out, err;
  ASSERT_EQ(run({"--version"}, &out, &err), 0) << err;
  EXPECT_EQ(out.rfind("arpipe 0.", 0), 0u) << out;  // the CMake project version, then git describe
  ASSERT_EQ(run({"--help"}, &out, &err), 0) << err;
  const std::vector<std::string> commands{"inspect", "replay", "simulate", "calib",  "board",  "bench", "sh",
                                          "bake",    "sun",    "cameras",  "record", "config", "ctl",
                                          "proxy"};
  for (const std::string& command : commands) {
    EXPECT_NE(out.find("  " + command + " "), std::string::npos) << command << "\n" << out;
    std::string help;
    EXPECT_EQ(run({command, "--help"}, &help, &err), 0) << command << ": " << err;
    EXPECT_NE(help.find("Usage: arpipe " + command), std::string::npos) << help;
  }
  if (!benchmarks_built()) return;
  for (const char* bench : {"pipeline", "scaling", "latency", "pose", "sim-render", "blur", "shadows", "probe", "sun",
                            "capture-path", "calib-corners", "calib-solve", "sh", "prt", "physics"}) {
    std::string help;
    EXPECT_EQ(run({"bench", bench, "--help"}, &help, &err), 0) << bench << ": " << err;
    EXPECT_NE(help.find(std::string("Usage: arpipe bench ") + bench), std::string::npos) << help;
  }
}

TEST_F(ArpipeCli, UsageErrorsExitTwoNamingTheOption) {
  std::string err;
  EXPECT_EQ(run({"bake", "builtin:cup", "--bands", "0"}, nullptr, &err), 2);
  EXPECT_NE(err.find("arpipe bake: --bands"), std::string::npos) << err;
  EXPECT_EQ(run({"simulate", "--scene", "x.toml"}, nullptr, &err), 2);
  EXPECT_NE(err.find("--out"), std::string::npos) << err;
  EXPECT_EQ(run({"replay", kCapture.string(), "--frobnicate"}, nullptr, &err), 2);
  EXPECT_NE(err.find("--frobnicate"), std::string::npos) << err;
  EXPECT_EQ(run({"sun", "--lat", "52", "--lon", "13", "--time", "2026-06-21T10:30:00Z", "--declination", "3"}, nullptr,
                &err),
            2);
  EXPECT_NE(err.find("--declination"), std::string::npos) << err;
}

// A bench's own options are parsed only where the benchmarks are built (-DARPIPE_BUILD_BENCH=ON);
// without them every `arpipe bench NAME` is the usage error that says how to get them.
TEST_F(ArpipeCli, BenchUsageErrorsExitTwoNamingTheOption) {
  std::string err;
  EXPECT_EQ(run({"bench", "sun", "--calls", "zero"}, nullptr, &err), 2);
  if (benchmarks_built())
    EXPECT_NE(err.find("--calls"), std::string::npos) << err;
  else
    EXPECT_NE(err.find("built without the benchmarks (cmake -DARPIPE_BUILD_BENCH=OFF)"), std::string::npos) << err;
}

TEST_F(ArpipeCli, BenchSunPrintsItsTable) {
  if (!benchmarks_built()) GTEST_SKIP() << "arpipe built without the benchmarks";
  std::string out, err;
  ASSERT_EQ(run({"bench", "sun", "--calls", "200", "--repeats", "3"}, &out, &err), 0) << err;
  EXPECT_NE(out.find("| NREL SPA (topocentric, refraction) |"), std::string::npos) << out;
  EXPECT_NE(out.find("| PSA (seed 001) |"), std::string::npos) << out;
}

// The physics table: at the default 960 substeps per second the ball's bounce is within the issue's
// 1 % of e^2 h (the tests in tests/physics hold the same bound).
TEST_F(ArpipeCli, BenchPhysicsPrintsItsTable) {
  if (!benchmarks_built()) GTEST_SKIP() << "arpipe built without the benchmarks";
  std::string out, err;
  ASSERT_EQ(run({"bench", "physics", "--seconds", "0.5"}, &out, &err), 0) << err;
  const size_t row = out.find("\n| 960 | ");
  ASSERT_NE(row, std::string::npos) << out;
  // "\n| 960 | MS | BOUNCE % | LANDING ms |": the separator after MS comes before BOUNCE.
  const size_t bounce_at = out.find(" | ", row + 8);
  ASSERT_NE(bounce_at, std::string::npos) << out;
  const double bounce_percent = std::stod(out.substr(bounce_at + 3));
  EXPECT_LT(bounce_percent, 1.0) << out;
}

TEST_F(ArpipeCli, DaemonPrintsItsVersionAndHelp) {
  std::string out, err;
  const int version = test::run_to_exit(test::build_program("arpiped"), {"--version"}, dir_ / "logs", &err);
  EXPECT_EQ(version, 0) << err;
  test::ChildProcess help(test::build_program("arpiped"), {"--help"}, dir_ / "logs");
  ASSERT_EQ(help.wait(), 0);
  EXPECT_NE(help.stdout_text().find("--config FILE"), std::string::npos) << help.stdout_text();
  EXPECT_NE(help.stdout_text().find("--set KEY=VALUE"), std::string::npos) << help.stdout_text();
  EXPECT_EQ(test::run_to_exit(test::build_program("arpiped"), {"--frobnicate"}, dir_ / "logs", &err), 2);
  EXPECT_NE(err.find("--frobnicate"), std::string::npos) << err;
}

// The numbers after "]: [" on the first line containing `label`.
std::vector<double> numbers_after(const std::string& text, const std::string& label) {
  std::vector<double> out;
  const size_t line = text.find(label);
  if (line == std::string::npos) return out;
  const char* p = text.c_str() + text.find("]: [", line) + 4;
  for (int i = 0; i < 3; ++i) {
    char* end = nullptr;
    out.push_back(std::strtod(p, &end));
    p = end + 1;
  }
  return out;
}

// A constant probe of radiance 0.5 (exact in RGBE): L00 = 0.5 sqrt(4 pi) = 1.77245 and, at any
// normal, E = pi L = 1.5708; 1e-4 relative: the per-texel sum is the midpoint rule, whose error on
// the zonal l = 2 term is 5e-5 of L00 at 256 rows.
TEST_F(ArpipeCli, ShPrintsTheCoefficientsAndIrradianceOfAProbeAndWritesItsReconstruction) {
  HdrImage sky;
  sky.width = 512;
  sky.height = 256;
  sky.rgb.assign(size_t(sky.width) * sky.height * 3, 0.5f);
  write_radiance_hdr(dir_ / "sky.hdr", sky);
  std::string out, err;
  ASSERT_EQ(run({"sh", "--environment", (dir_ / "sky.hdr").string(), "--layout", "equirect", "--normal", "0.3,-0.2,1",
                 "--reconstruct", (dir_ / "back.hdr").string()},
                &out, &err),
            0)
      << err;
  EXPECT_NE(out.find("    0   0   0       1.77245      1.77245      1.77245"), std::string::npos) << out;
  const std::vector<double> e = numbers_after(out, "irradiance at normal");
  ASSERT_EQ(e.size(), 3u) << out;
  for (double v : e) EXPECT_NEAR(v, M_PI * 0.5, 1e-4 * M_PI * 0.5) << out;
  const HdrImage back = read_radiance_hdr(dir_ / "back.hdr");
  ASSERT_EQ(back.width, 512);
  // The 3-band reconstruction of a constant is the constant, within the same 1e-4 and RGBE's
  // truncation of up to 2^-8 of the value.
  for (float v : back.rgb) EXPECT_NEAR(v, 0.5, 0.5 * (1e-4 + 1.0 / 256));
}

TEST_F(ArpipeCli, ShRefusesAProbeWhoseShapeDoesNotFitTheLayoutNamingTheFile) {
  HdrImage sky;
  sky.width = 64;
  sky.height = 32;
  sky.rgb.assign(size_t(sky.width) * sky.height * 3, 0.5f);
  write_radiance_hdr(dir_ / "wide.hdr", sky);
  std::string out, err;
  EXPECT_EQ(run({"sh", "--probe", (dir_ / "wide.hdr").string(), "--layout", "angular"}, &out, &err), 1);
  EXPECT_NE(err.find("wide.hdr"), std::string::npos) << err;
  EXPECT_EQ(run({"sh", "--probe", (dir_ / "wide.hdr").string(), "--layout", "fisheye"}, &out, &err), 2);
  EXPECT_NE(err.find("--layout"), std::string::npos) << err;
}

TEST_F(ArpipeCli, BakeCachesTheTransferAndDoesNotBakeAnUnchangedMeshAgain) {
  const fs::path cache = dir_ / "cache";
  std::string out, err;
  ASSERT_EQ(run({"bake", "builtin:cup", "--samples", "8", "--cache-dir", cache.string()}, &out, &err), 0) << err;
  EXPECT_NE(out.find("baked in"), std::string::npos) << out;
  ASSERT_EQ(std::distance(fs::directory_iterator(cache), fs::directory_iterator()), 1);
  ASSERT_EQ(run({"bake", "builtin:cup", "--samples", "8", "--cache-dir", cache.string()}, &out, &err), 0) << err;
  EXPECT_NE(out.find("up to date (not baked)"), std::string::npos) << out;
  // Other settings are another key: a second file.
  ASSERT_EQ(run({"bake", "builtin:cup", "--samples", "8", "--kind", "unshadowed", "--cache-dir", cache.string()}, &out,
                &err),
            0)
      << err;
  EXPECT_EQ(std::distance(fs::directory_iterator(cache), fs::directory_iterator()), 2);
  EXPECT_EQ(run({"bake", (dir_ / "missing.gltf").string(), "--cache-dir", cache.string()}, &out, &err), 1);
  EXPECT_NE(err.find("missing.gltf"), std::string::npos) << err;
}

}  // namespace
