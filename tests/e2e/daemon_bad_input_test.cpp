// Bad input to the real arpiped process: a clear message naming the file and the place, exit
// status 2 for setup errors, never a crash; and the signals: SIGTERM drains, SIGHUP reloads.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <thread>

#include "capture/recording/recording_reader.h"
#include "tests/e2e/child_process.h"
#include "tests/e2e/e2e_test_dir.h"

namespace fs = std::filesystem;
using namespace arpipe;

namespace {

const fs::path& kCapture = test::kDefaultCapture;

class DaemonInput : public test::E2eTestDir {
 protected:
  int run(const fs::path& config, std::string& err, std::vector<std::string> extra = {}) {
    std::vector<std::string> args{"--config", config.string()};
    args.insert(args.end(), extra.begin(), extra.end());
    return test::run_to_exit(test::build_program("arpiped"), args, dir_ / "logs", &err);
  }
  size_t result_lines() { return test::count_lines(dir_ / "results.jsonl"); }
};

TEST_F(DaemonInput, MissingConfigFile) {
  std::string err;
  EXPECT_EQ(run(dir_ / "nope.toml", err), 2);
  EXPECT_NE(err.find("nope.toml"), std::string::npos) << err;
}

TEST_F(DaemonInput, CorruptConfigNamesLine) {
  const fs::path path = dir_ / "bad.toml";
  std::ofstream(path) << "[source]\npath = \"x\"\npacing = = 3\n";
  std::string err;
  EXPECT_EQ(run(path, err), 2);
  EXPECT_NE(err.find("bad.toml"), std::string::npos) << err;
  EXPECT_NE(err.find("3"), std::string::npos) << "line 3 should be named: " << err;
}

TEST_F(DaemonInput, UnknownConfigKey) {
  const fs::path path = write_config(kCapture, "[track]\nfamly = \"tag36h11\"\n");
  std::string err;
  EXPECT_EQ(run(path, err), 2);
  EXPECT_NE(err.find("arpipe.toml"), std::string::npos) << err;
  EXPECT_NE(err.find("track.famly"), std::string::npos) << err;
}

TEST_F(DaemonInput, MissingRecording) {
  std::string err;
  EXPECT_EQ(run(write_config(dir_ / "no-such-capture"), err), 2);
  EXPECT_NE(err.find("no-such-capture"), std::string::npos) << err;
}

TEST_F(DaemonInput, TruncatedRecordingReplaysItsCompleteFrames) {
  const fs::path capture = copy_capture();
  const size_t n = RecordingReader(kCapture).frame_count();
  // Cut frames.bin in the middle of the last frame's pixels.
  const auto size = fs::file_size(capture / "frames.bin");
  const size_t frame_bytes = size / n;
  fs::resize_file(capture / "frames.bin", size - frame_bytes / 2);
  std::string err;
  EXPECT_EQ(run(write_config(capture), err), 0) << err;
  EXPECT_NE(err.find("warning"), std::string::npos) << err;
  EXPECT_EQ(result_lines(), n - 1);
}

TEST_F(DaemonInput, CorruptRecordingMetadataNamesFileAndLine) {
  const fs::path capture = copy_capture();
  // Damage line 3 of the per-frame metadata (not the last line: that would read as a cut-off tail).
  std::ifstream in(capture / "frames.jsonl");
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  in.close();
  ASSERT_GT(lines.size(), 5u);
  lines[2] = "{\"index\": 2, garbage";
  std::ofstream out(capture / "frames.jsonl", std::ios::trunc);
  for (const auto& l : lines) out << l << "\n";
  out.close();
  std::string err;
  EXPECT_EQ(run(write_config(capture), err), 2);
  EXPECT_NE(err.find("frames.jsonl"), std::string::npos) << err;
  EXPECT_NE(err.find("3"), std::string::npos) << err;
}

TEST_F(DaemonInput, UnsupportedPixelFormat) {
  const fs::path capture = copy_capture();
  nlohmann::json info = nlohmann::json::parse(test::read_text(capture / "recording.json"));
  info["pixel_format"] = "MJPG";
  std::ofstream(capture / "recording.json", std::ios::trunc) << info.dump(2);
  std::string err;
  EXPECT_EQ(run(write_config(capture), err), 2);
  EXPECT_NE(err.find("recording.json"), std::string::npos) << err;
  EXPECT_NE(err.find("MJPG"), std::string::npos) << err;
}

TEST_F(DaemonInput, MissingCameraModel) {
  const fs::path capture = copy_capture();
  fs::remove(capture / "camera.cameramodel");
  std::string err;
  EXPECT_EQ(run(write_config(capture), err), 2);
  EXPECT_NE(err.find("camera.cameramodel"), std::string::npos) << err;
}

TEST_F(DaemonInput, CorruptCameraModel) {
  const fs::path capture = copy_capture();
  std::ofstream(capture / "camera.cameramodel", std::ios::trunc) << "{ 'lensmodel': 'LENSMODEL_OPENCV4', 'intri";
  std::string err;
  EXPECT_EQ(run(write_config(capture), err), 2);
  EXPECT_NE(err.find("camera.cameramodel"), std::string::npos) << err;
}

TEST_F(DaemonInput, MissingAsset) {
  const fs::path config =
      write_config(kCapture, "[[render.objects]]\nmesh = \"" + (dir_ / "missing.gltf").string() + "\"\n");
  std::string err;
  EXPECT_EQ(run(config, err), 2);
  EXPECT_NE(err.find("missing.gltf"), std::string::npos) << err;
}

// SIGTERM while frames flow: the daemon drains its queues and flushes, so every frame it took in
// reached every sink, and it exits 0.
TEST_F(DaemonInput, SigtermDrainsAndFlushes) {
  const fs::path config = write_config(kCapture, "");
  test::ChildProcess child(test::build_program("arpiped"),
                           {"--config", config.string(), "--set", "source.pacing=\"timestamps\"", "--set",
                            "source.loop=true"},
                           dir_ / "logs");
  ASSERT_TRUE(child.wait_for_stderr("arpiped: info: running")) << child.stderr_text();
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));  // frames flowing
  child.signal(SIGTERM);
  const int status = child.wait(std::chrono::seconds(30));
  ASSERT_NE(status, -1) << "did not stop";
  ASSERT_TRUE(WIFEXITED(status)) << child.stderr_text();
  EXPECT_EQ(WEXITSTATUS(status), 0) << child.stderr_text();
  const size_t lines = result_lines();
  EXPECT_GT(lines, 0u);
  size_t pngs = 0;
  for (const auto& e : fs::directory_iterator(dir_ / "png")) pngs += e.path().extension() == ".png";
  EXPECT_EQ(pngs, lines);
  RecordingReader reader(kCapture);
  const size_t frame_bytes = 6 + size_t(reader.info().width) * reader.info().height * 3 / 2;
  std::ifstream y4m(dir_ / "out.y4m", std::ios::binary);
  std::string header;
  std::getline(y4m, header);
  EXPECT_EQ(fs::file_size(dir_ / "out.y4m"), header.size() + 1 + lines * frame_bytes);
}

// SIGHUP with a broken config is refused and the daemon keeps running; a good one is accepted.
TEST_F(DaemonInput, SighupReloadRefusesBadConfigAndKeepsRunning) {
  const fs::path config = write_config(kCapture, "");
  test::ChildProcess child(test::build_program("arpiped"),
                           {"--config", config.string(), "--set", "source.pacing=\"timestamps\"", "--set",
                            "source.loop=true"},
                           dir_ / "logs");
  ASSERT_TRUE(child.wait_for_stderr("arpiped: info: running")) << child.stderr_text();
  const std::string good = test::read_text(config);
  std::ofstream(config, std::ios::trunc) << good << "[track]\nno_such_key = 1\n";
  child.signal(SIGHUP);
  EXPECT_TRUE(child.wait_for_stderr("reload refused")) << child.stderr_text();
  EXPECT_NE(child.stderr_text().find("no_such_key"), std::string::npos) << child.stderr_text();
  std::ofstream(config, std::ios::trunc) << good << "[render]\nlight_direction = [0.0, 0.0, 1.0]\n";
  child.signal(SIGHUP);
  EXPECT_TRUE(child.wait_for_stderr("reload applied: render")) << child.stderr_text();
  child.signal(SIGTERM);
  const int status = child.wait(std::chrono::seconds(30));
  ASSERT_TRUE(status != -1 && WIFEXITED(status)) << child.stderr_text();
  EXPECT_EQ(WEXITSTATUS(status), 0);
}

}  // namespace
