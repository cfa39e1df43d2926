// Hostile inputs to the real programs (issue 18, findings 8-10): tiny inputs that declared huge
// allocations, messages that named no file or key, a --set that injected TOML, config --check that
// said "ok" for a missing mesh, and a FIFO as frames.bin that blocked arpiped's start.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "tests/e2e/child_process.h"
#include "tests/e2e/e2e_test_dir.h"

namespace fs = std::filesystem;
using namespace arpipe;

namespace {

const fs::path& kCapture = test::kDefaultCapture;

class HardeningInputs : public test::E2eTestDir {
 protected:
  // Exit status of a program of the build, -1000 when it ran past `timeout` (then killed).
  int run(const std::string& program, const std::vector<std::string>& args, std::string& err,
          std::chrono::seconds timeout = std::chrono::seconds(60)) {
    test::ChildProcess child(test::build_program(program), args, dir_ / "logs");
    const int status = child.wait(timeout);
    err = child.stderr_text();
    if (status == -1) return -1000;
    if (WIFSIGNALED(status)) return -WTERMSIG(status);
    return WEXITSTATUS(status);
  }
  static bool contains(const std::string& text, const std::string& part) {
    return text.find(part) != std::string::npos;
  }
};

TEST_F(HardeningInputs, ConfigCheckNamesAMissingMeshByItsKey) {
  std::string err;
  const fs::path good = write_config(kCapture, "[[render.objects]]\nmesh = \"builtin:cube\"\n");
  EXPECT_EQ(run("arpipe", {"config", "--check", good.string()}, err), 0) << err;
  // Before: "ok", and arpiped then failed at start.
  const fs::path bad = write_config(kCapture, "[[render.objects]]\nmesh = \"builtin:cube\"\n[[render.objects]]\nmesh = \"" +
                                                  (dir_ / "cup.glb").string() + "\"\n");
  EXPECT_EQ(run("arpipe", {"config", "--check", bad.string()}, err), 2);
  EXPECT_TRUE(contains(err, bad.string() + ": render.objects[1].mesh: " + (dir_ / "cup.glb").string() +
                                ": No such file or directory"))
      << err;
}

TEST_F(HardeningInputs, ASetValueWithANewlineIsRefused) {
  std::string err;
  const fs::path config = write_config(kCapture);
  // Before: the newline ended the value and [sinks.png] with its dir became part of the config.
  EXPECT_EQ(run("arpiped", {"--config", config.string(), "--set",
                            "pipeline.max_frames=1\n[sinks.results]\npath = \"/tmp/injected.jsonl\""},
                err),
            2);
  EXPECT_TRUE(contains(err, "the value of 'pipeline.max_frames' contains a newline")) << err;
  EXPECT_TRUE(contains(err, "override 'pipeline.max_frames=1\\n[sinks.results]")) << err;
  EXPECT_FALSE(fs::exists(dir_ / "results.jsonl"));
}

TEST_F(HardeningInputs, OutOfRangeNumbersAndOffsetsSayOutOfRange) {
  std::string err;
  const fs::path config = write_config(kCapture);
  EXPECT_EQ(run("arpiped", {"--config", config.string(), "--set", "render.lens_canvas_scale=1e400"}, err), 2);
  EXPECT_TRUE(contains(err, "render.lens_canvas_scale: expected a number within a 64-bit float (magnitude at most about "
                            "1.8e308), found 1e400"))
      << err;
  EXPECT_EQ(run("arpiped", {"--config", config.string(), "--set", "source.timestamp_offset_ns=9223372036854775807"},
                err),
            2);
  EXPECT_TRUE(contains(err, "source.timestamp_offset_ns: expected an integer in [-3600000000000, 3600000000000], found "
                            "9223372036854775807"))
      << err;
}

TEST_F(HardeningInputs, AFifoAsFramesBinFailsTheStartAtOnce) {
  const fs::path capture = dir_ / "capture";
  fs::create_directories(capture);
  for (const char* name : {"recording.json", "camera.cameramodel", "frames.jsonl"})
    fs::copy_file(kCapture / name, capture / name);
  ASSERT_EQ(::mkfifo((capture / "frames.bin").c_str(), 0600), 0);
  std::string err;
  // Before: open() blocked forever and SIGTERM was ignored while it did.
  EXPECT_EQ(run("arpiped", {"--config", write_config(capture).string()}, err, std::chrono::seconds(20)), 2) << err;
  EXPECT_TRUE(contains(err, (capture / "frames.bin").string() + ": cannot read recording file: it is a FIFO")) << err;
}

TEST_F(HardeningInputs, AnEmptySourcePathAndASymlinkLoopAreNamed) {
  std::string err;
  // Before: ": not a recording (no such directory)".
  EXPECT_EQ(run("arpiped", {"--config", write_config("").string()}, err), 2);
  EXPECT_TRUE(contains(err, "source.path is empty")) << err;
  fs::create_symlink(dir_ / "loop_b", dir_ / "loop_a");
  fs::create_symlink(dir_ / "loop_a", dir_ / "loop_b");
  // Before: std::filesystem's raw "filesystem error: ..." text.
  EXPECT_EQ(run("arpiped", {"--config", write_config(dir_ / "loop_a").string()}, err), 2);
  EXPECT_TRUE(contains(err, (dir_ / "loop_a").string() + ": Too many levels of symbolic links")) << err;
  EXPECT_FALSE(contains(err, "filesystem error")) << err;
  EXPECT_EQ(run("arpiped", {"--config", (dir_ / "loop_a").string()}, err), 2);
  EXPECT_TRUE(contains(err, (dir_ / "loop_a").string() + ": cannot read config: Too many levels of symbolic links"))
      << err;
}

TEST_F(HardeningInputs, SimulateRefusesAHugeFrameBeforeRendering) {
  std::ofstream(dir_ / "huge.toml") << "[camera]\nwidth = 16384\nheight = 16384\n";
  std::string err;
  // Before: accepted, and the simulator grew past 21 GB.
  EXPECT_EQ(run("arpipe", {"simulate", "--scene", (dir_ / "huge.toml").string(), "--out", (dir_ / "out").string()}, err,
                std::chrono::seconds(30)),
            2);
  EXPECT_TRUE(contains(err, "huge.toml:2:9: camera.width: expected a simulated frame of at most 8192 pixels a side"))
      << err;
  EXPECT_FALSE(fs::exists(dir_ / "out"));
}

}  // namespace
