// Signals to the real arpiped process at the awkward moments: during a setup that hangs on a FIFO or
// runs long (a PRT bake), during a reload that is still loading, and a Y4M reader that goes away
// (SIGPIPE). The daemon must end within a second of SIGTERM, never die of a signal, and keep
// drawing frames while a reload loads.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "tests/e2e/child_process.h"
#include "tests/e2e/e2e_test_dir.h"

namespace fs = std::filesystem;
using namespace arpipe;
using Clock = std::chrono::steady_clock;

namespace {

const fs::path& kCapture = test::kDefaultCapture;

// "Within a second" of the requirement for a setup, with room for a loaded test machine.
constexpr double kPromptSeconds = 1.5;
// A running daemon first drains its queues through every stage (a few frames, slow while a bake
// takes every core); far less than the bake it must not wait for.
constexpr double kDrainSeconds = 5.0;

// Objects whose PRT bakes (the most directions the config allows, self-shadowed and
// interreflected, into an empty cache) keep the daemon's setup or a reload busy for about 15 s here
// (2 cores): long enough that signals land in the middle of it on a much faster machine too.
std::string slow_prt_objects(const fs::path& cache_dir) {
  std::string toml = "[render.prt]\nsamples = 256\ncache_dir = \"" + cache_dir.string() + "\"\n";
  for (const char* mesh : {"builtin:sphere", "builtin:cup", "builtin:cube", "builtin:pyramid"})
    for (const char* prt : {"interreflected", "shadowed"})
      toml += std::string("[[render.objects]]\nmesh = \"") + mesh + "\"\nprt = \"" + prt + "\"\n";
  return toml;
}

struct Ending {
  int status = -1;  // wait status, -1 when it did not end (it was then killed)
  double seconds = 0;
};

class DaemonSignals : public test::E2eTestDir {
 protected:
  fs::path make_fifo(const std::string& name) {
    const fs::path path = dir_ / name;
    EXPECT_EQ(mkfifo(path.c_str(), 0600), 0) << path << ": " << std::strerror(errno);
    return path;
  }
  // A config whose outputs all land in this test's directory; `y4m` may name a FIFO.
  fs::path write_config(const fs::path& capture, const std::string& extra = "", fs::path y4m = {}) {
    if (y4m.empty()) y4m = dir_ / "out.y4m";
    const fs::path path = dir_ / "arpipe.toml";
    std::ofstream(path) << "[source]\npath = \"" << capture.string() << "\"\n"
                        << "[sinks.y4m]\npath = \"" << y4m.string() << "\"\n"
                        << "[sinks.results]\npath = \"" << (dir_ / "results.jsonl").string() << "\"\n"
                        << extra;
    return path;
  }
  // The default capture, looped at its own frame rate: a daemon that runs until it is stopped.
  // Returns once the daemon answers signals (loading its libraries alone takes most of a second
  // here; a signal before that ends it by the default action).
  std::unique_ptr<test::ChildProcess> start(const fs::path& config) {
    auto child = std::make_unique<test::ChildProcess>(
        test::build_program("arpiped"),
        std::vector<std::string>{"--config", config.string(), "--set", "source.pacing=\"timestamps\"", "--set",
                                 "source.loop=true"},
        dir_ / "logs");
    EXPECT_TRUE(child->wait_for_stderr("arpiped: info: setting up from")) << child->stderr_text();
    return child;
  }
  static Ending signal_and_time(test::ChildProcess& child, int sig) {
    const auto sent = Clock::now();
    child.signal(sig);
    Ending ending;
    ending.status = child.wait(std::chrono::seconds(20));
    ending.seconds = std::chrono::duration<double>(Clock::now() - sent).count();
    return ending;
  }
  // The setup must be stoppable however far it got: stopped (0, logged) or already failed with a
  // setup error naming the file (2, when a loader refuses the FIFO before the signal), never a
  // crash, never slower than kPromptSeconds.
  static void expect_stopped_promptly(const Ending& ending, const test::ChildProcess& child, const std::string& file) {
    const std::string err = child.stderr_text();
    ASSERT_NE(ending.status, -1) << "did not end within 20 s of the signal: " << err;
    EXPECT_LE(ending.seconds, kPromptSeconds) << err;
    ASSERT_TRUE(WIFEXITED(ending.status)) << "died of signal " << WTERMSIG(ending.status) << ": " << err;
    const int code = WEXITSTATUS(ending.status);
    if (code == 0)
      EXPECT_NE(err.find("during setup"), std::string::npos) << err;
    else {
      EXPECT_EQ(code, 2) << err;
      EXPECT_NE(err.find(file), std::string::npos) << err;
    }
  }
  size_t result_lines() const { return test::count_lines(dir_ / "results.jsonl"); }
  // Waits until results.jsonl holds more than `lines` lines: frames are still being drawn.
  bool frames_flow_past(size_t lines, std::chrono::seconds timeout) const {
    const auto deadline = Clock::now() + timeout;
    while (result_lines() <= lines)
      if (Clock::now() > deadline) return false;
      else std::this_thread::sleep_for(std::chrono::milliseconds(20));
    return true;
  }
};

// A recording whose frames.bin is a FIFO that nobody writes: open() would wait forever.
TEST_F(DaemonSignals, SigtermEndsASetupBlockedOnAFifoRecording) {
  const fs::path capture = copy_capture();
  fs::remove(capture / "frames.bin");
  ASSERT_EQ(mkfifo((capture / "frames.bin").c_str(), 0600), 0);
  auto child = start(write_config(capture));
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // into the setup step that blocks
  expect_stopped_promptly(signal_and_time(*child, SIGTERM), *child, "frames.bin");
}

// A mesh file that is a FIFO: the glTF loader's open() waits for a writer that never comes.
TEST_F(DaemonSignals, SigtermEndsASetupBlockedOnAFifoMesh) {
  const fs::path mesh = make_fifo("mesh.gltf");
  auto child = start(write_config(kCapture, "[[render.objects]]\nmesh = \"" + mesh.string() + "\"\n"));
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // into the setup step that blocks
  expect_stopped_promptly(signal_and_time(*child, SIGTERM), *child, "mesh.gltf");
}

// A Y4M output on a FIFO that nobody reads: opening it for writing waits for a reader.
TEST_F(DaemonSignals, SigintEndsASetupBlockedOnAFifoOutputWithoutReader) {
  const fs::path y4m = make_fifo("out.y4m");
  auto child = start(write_config(kCapture, "", y4m));
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // into the setup step that blocks
  expect_stopped_promptly(signal_and_time(*child, SIGINT), *child, "out.y4m");
}

// Not stuck but slow: a PRT bake of many directions into an empty cache, the kind of setup step
// that runs for seconds on the board. The signal must not wait for it, and the outputs of an
// earlier run are left as they were (the run never came up).
TEST_F(DaemonSignals, SigtermEndsASlowPrtBakeAndKeepsThePreviousOutputs) {
  std::ofstream(dir_ / "results.jsonl") << "{\"previous\": \"run\"}\n";
  const fs::path config = write_config(kCapture, slow_prt_objects(dir_ / "prt-cache"));
  auto child = start(config);
  std::this_thread::sleep_for(std::chrono::milliseconds(500));  // into the bake
  const Ending ending = signal_and_time(*child, SIGTERM);
  const std::string err = child->stderr_text();
  ASSERT_NE(ending.status, -1) << err;
  ASSERT_TRUE(WIFEXITED(ending.status)) << "died of signal " << WTERMSIG(ending.status) << ": " << err;
  EXPECT_EQ(WEXITSTATUS(ending.status), 0) << err;
  EXPECT_LE(ending.seconds, kPromptSeconds) << err;
  EXPECT_NE(err.find("SIGTERM during setup"), std::string::npos) << err;
  EXPECT_EQ(err.find("arpiped: info: running"), std::string::npos) << "the bake should still have been running: " << err;
  EXPECT_EQ(test::read_text(dir_ / "results.jsonl"), "{\"previous\": \"run\"}\n");
}

// A Y4M reader that takes a few frames and leaves: the next write gets EPIPE (SIGPIPE is ignored),
// the daemon keeps running and exits 0 on SIGTERM.
TEST_F(DaemonSignals, Y4mReaderThatLeavesDoesNotKillTheDaemon) {
  const fs::path y4m = make_fifo("out.y4m");
  // Opened before the daemon starts (non-blocking, so it needs no writer yet): the daemon's open
  // for writing then finds a reader.
  // O_CLOEXEC: a daemon that inherited the read end would never see its reader leave.
  const int reader = open(y4m.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  ASSERT_GE(reader, 0) << std::strerror(errno);
  auto child = start(write_config(kCapture, "", y4m));
  // Read until a few frames' worth came (or give up), then go away.
  const nlohmann::json info = nlohmann::json::parse(test::read_text(kCapture / "recording.json"));
  const size_t wanted = 3 * info.at("width").get<size_t>() * info.at("height").get<size_t>() * 3 / 2;
  size_t got = 0;
  std::vector<char> buffer(1 << 16);
  const auto deadline = Clock::now() + std::chrono::seconds(60);
  while (got < wanted && Clock::now() < deadline) {
    const ssize_t n = read(reader, buffer.data(), buffer.size());
    if (n > 0) got += size_t(n);
    else std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  close(reader);
  EXPECT_GE(got, wanted) << child->stderr_text();
  ASSERT_TRUE(child->wait_for_stderr("arpiped: info: running")) << child->stderr_text();
  // Frames keep being drawn after the reader left (and the sink's writes fail).
  const size_t lines = result_lines();
  EXPECT_TRUE(frames_flow_past(lines + 10, std::chrono::seconds(30))) << child->stderr_text();
  const Ending ending = signal_and_time(*child, SIGTERM);
  const std::string err = child->stderr_text();
  ASSERT_NE(ending.status, -1) << err;
  ASSERT_TRUE(WIFEXITED(ending.status)) << "died of signal " << WTERMSIG(ending.status) << ": " << err;
  EXPECT_EQ(WEXITSTATUS(ending.status), 0) << err;
}

// A reload whose assets take seconds to load (a PRT bake of many directions) loads beside the
// running pipeline: frames keep coming while it loads, SIGTERM meanwhile is prompt, and a newer
// SIGHUP supersedes it.
TEST_F(DaemonSignals, SlowReloadLoadsBesideTheRunningPipelineAndIsSuperseded) {
  const fs::path config = write_config(kCapture);
  const std::string good = test::read_text(config);
  auto child = start(config);
  ASSERT_TRUE(child->wait_for_stderr("arpiped: info: running", std::chrono::seconds(120))) << child->stderr_text();
  ASSERT_TRUE(frames_flow_past(0, std::chrono::seconds(30))) << child->stderr_text();

  std::ofstream(config, std::ios::trunc) << good << slow_prt_objects(dir_ / "prt-cache");
  child->signal(SIGHUP);
  ASSERT_TRUE(child->wait_for_stderr("SIGHUP: reloading")) << child->stderr_text();
  // While the bake runs (on every core), the processing thread keeps drawing frames under the
  // running config.
  const size_t lines = result_lines();
  EXPECT_TRUE(frames_flow_past(lines + 5, std::chrono::seconds(10))) << child->stderr_text();
  EXPECT_EQ(child->stderr_text().find("reload applied"), std::string::npos) << "the bake was expected to take longer";

  // A newer SIGHUP (the old config again) is applied, and the slow one is never applied.
  std::ofstream(config, std::ios::trunc) << good;
  child->signal(SIGHUP);
  EXPECT_TRUE(child->wait_for_stderr("supersedes the reload still loading")) << child->stderr_text();
  EXPECT_TRUE(child->wait_for_stderr("reload applied: no key changed")) << child->stderr_text();

  // The superseded bake is still running: SIGTERM does not wait for it.
  const Ending ending = signal_and_time(*child, SIGTERM);
  const std::string err = child->stderr_text();
  ASSERT_NE(ending.status, -1) << err;
  ASSERT_TRUE(WIFEXITED(ending.status)) << "died of signal " << WTERMSIG(ending.status) << ": " << err;
  EXPECT_EQ(WEXITSTATUS(ending.status), 0) << err;
  EXPECT_LE(ending.seconds, kDrainSeconds) << err;
  // Exactly one reload was applied: the newer one.
  size_t accepted = 0;
  for (size_t at = err.find("reload applied"); at != std::string::npos; at = err.find("reload applied", at + 1))
    ++accepted;
  EXPECT_EQ(accepted, 1u) << err;
}

// A reload naming a FIFO as its mesh: stuck for good where the loader opens it (or refused at once
// where the glTF loader refuses FIFOs, as it now does); either way frames keep coming, it is never
// accepted, and the daemon still stops at once.
TEST_F(DaemonSignals, ReloadStuckOnAFifoMeshNeitherStallsFramesNorStop) {
  const fs::path config = write_config(kCapture);
  const std::string good = test::read_text(config);
  auto child = start(config);
  ASSERT_TRUE(child->wait_for_stderr("arpiped: info: running", std::chrono::seconds(120))) << child->stderr_text();
  const fs::path mesh = make_fifo("mesh.gltf");
  std::ofstream(config, std::ios::trunc) << good << "[[render.objects]]\nmesh = \"" << mesh.string() << "\"\n";
  child->signal(SIGHUP);
  ASSERT_TRUE(child->wait_for_stderr("SIGHUP: reloading")) << child->stderr_text();
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const size_t lines = result_lines();
  EXPECT_TRUE(frames_flow_past(lines + 15, std::chrono::seconds(5))) << child->stderr_text();
  const Ending ending = signal_and_time(*child, SIGTERM);
  const std::string err = child->stderr_text();
  ASSERT_NE(ending.status, -1) << err;
  ASSERT_TRUE(WIFEXITED(ending.status)) << "died of signal " << WTERMSIG(ending.status) << ": " << err;
  EXPECT_EQ(WEXITSTATUS(ending.status), 0) << err;
  EXPECT_LE(ending.seconds, kDrainSeconds) << err;
  EXPECT_EQ(err.find("reload applied"), std::string::npos) << err;
}

// Finding 9: a missing mesh names the config key as well as the file.
TEST_F(DaemonSignals, MissingMeshNamesTheConfigKey) {
  const fs::path config = write_config(
      kCapture, "[[render.objects]]\nmesh = \"builtin:cube\"\n[[render.objects]]\nmesh = \"" +
                    (dir_ / "missing.gltf").string() + "\"\n");
  std::string err;
  EXPECT_EQ(test::run_to_exit(test::build_program("arpiped"), {"--config", config.string()}, dir_ / "logs", &err), 2);
  EXPECT_NE(err.find("missing.gltf"), std::string::npos) << err;
  EXPECT_NE(err.find("render.objects[1].mesh"), std::string::npos) << err;  // counted from 0
  EXPECT_NE(err.find("arpipe.toml"), std::string::npos) << err;
}

}  // namespace
