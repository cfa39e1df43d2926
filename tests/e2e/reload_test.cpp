// SIGHUP reloads through the real arpiped, one test per kind of change: a sink added, removed or
// re-pointed (the old output flushed and complete, the new one written from the boundary on, the
// unchanged ones never restarted), the light source switched from fixed to the sun and back, and a
// change that needs a restart refused by name while the running config goes on. Every frame is
// accounted for in the outputs, not only in the log.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "tests/e2e/child_process.h"
#include "tests/e2e/e2e_test_dir.h"

namespace fs = std::filesystem;
using namespace arpipe;
using Clock = std::chrono::steady_clock;

namespace {

std::vector<nlohmann::json> read_jsonl(const fs::path& path) {
  std::vector<nlohmann::json> lines;
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);) lines.push_back(nlohmann::json::parse(line));
  return lines;
}

// The indices of the PNG frames in `dir` (frame_000042.png: 42).
std::set<uint64_t> png_indices(const fs::path& dir) {
  std::set<uint64_t> indices;
  if (!fs::exists(dir)) return indices;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("frame_", 0) == 0 && entry.path().extension() == ".png")
      indices.insert(std::stoull(name.substr(6, name.size() - 10)));
  }
  return indices;
}

class Reload : public test::E2eTestDir {
 protected:
  // The default capture looped at its own frame rate (the daemon runs until it is stopped), with
  // results.jsonl in this test's directory and `rest` (the other sinks, light) after it.
  void write(const std::string& rest) const {
    std::ofstream(config_path()) << "[source]\npath = \"" << test::kDefaultCapture.string()
                                 << "\"\npacing = \"timestamps\"\nloop = true\n"
                                 << "[sinks.results]\npath = \"" << results_path().string() << "\"\n"
                                 << "[sinks.recording]\nenabled = false\n"
                                 << rest;
  }
  fs::path config_path() const { return dir_ / "arpipe.toml"; }
  fs::path results_path() const { return dir_ / "results.jsonl"; }
  std::string y4m(const std::string& name) const {
    return "[sinks.y4m]\nenabled = true\npath = \"" + (dir_ / name).string() + "\"\n";
  }
  static std::string no_y4m() { return "[sinks.y4m]\nenabled = false\n"; }
  std::string png(const std::string& name) const {
    return "[sinks.png]\nenabled = true\ndir = \"" + (dir_ / name).string() + "\"\n";
  }
  static std::string no_png() { return "[sinks.png]\nenabled = false\n"; }

  // Starts the daemon on the config written last and waits until frames reach results.jsonl.
  void start() {
    child_ = std::make_unique<test::ChildProcess>(test::build_program("arpiped"),
                                                  std::vector<std::string>{"--config", config_path().string()},
                                                  dir_ / "logs");
    ASSERT_TRUE(child_->wait_for_stderr("arpiped: info: running")) << child_->stderr_text();
    ASSERT_TRUE(frames_flow_past(3)) << child_->stderr_text();
  }
  // Rewrites the config, sends SIGHUP and waits for the answer, which must hold `answer`.
  void reload(const std::string& rest, const std::string& answer) {
    const size_t before = answers();
    write(rest);
    child_->signal(SIGHUP);
    const auto deadline = Clock::now() + std::chrono::seconds(20);
    while (answers() == before && Clock::now() < deadline) std::this_thread::sleep_for(std::chrono::milliseconds(20));
    const std::string err = child_->stderr_text();
    ASSERT_GT(answers(), before) << "no answer to the SIGHUP: " << err;
    EXPECT_NE(err.rfind(answer), std::string::npos) << err;
  }
  size_t answers() const {
    const std::string err = child_->stderr_text();
    return count(err, "reload applied") + count(err, "reload refused");
  }
  static size_t count(const std::string& text, const std::string& what) {
    size_t n = 0;
    for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
    return n;
  }
  size_t result_lines() const { return test::count_lines(results_path()); }
  // Waits until results.jsonl holds more than `lines` lines.
  bool frames_flow_past(size_t lines) const {
    const auto deadline = Clock::now() + std::chrono::seconds(20);
    while (result_lines() <= lines)
      if (Clock::now() > deadline) return false;
      else std::this_thread::sleep_for(std::chrono::milliseconds(20));
    return true;
  }
  // SIGTERM; the daemon must drain, flush and exit 0. Returns every frame's results line.
  std::vector<nlohmann::json> stop() {
    child_->signal(SIGTERM);
    const int status = child_->wait(std::chrono::seconds(30));
    const std::string err = child_->stderr_text();
    EXPECT_TRUE(status != -1 && WIFEXITED(status) && WEXITSTATUS(status) == 0) << err;
    std::vector<nlohmann::json> results = read_jsonl(results_path());
    // Every frame from the first on, once each: nothing was lost by the reloads.
    for (size_t i = 0; i < results.size(); ++i) EXPECT_EQ(results[i]["index"].get<uint64_t>(), i);
    return results;
  }
  // The frames of a Y4M file, which must hold whole frames only (after its header).
  static size_t y4m_frames(const fs::path& path) {
    const nlohmann::json info = nlohmann::json::parse(test::read_text(test::kDefaultCapture / "recording.json"));
    const size_t frame_bytes = 6 + info.at("width").get<size_t>() * info.at("height").get<size_t>() * 3 / 2;
    const std::string text = test::read_text(path);
    const size_t header = text.find('\n') + 1;
    EXPECT_EQ(text.rfind("YUV4MPEG2 ", 0), 0u) << path;
    EXPECT_EQ((text.size() - header) % frame_bytes, 0u) << path << " ends inside a frame";
    return (text.size() - header) / frame_bytes;
  }

  std::unique_ptr<test::ChildProcess> child_;
};

// The PNG sink added by a reload writes every frame from the boundary on; the Y4M sink, whose
// section did not change, runs on untouched: it holds every frame of the run, none restarted.
TEST_F(Reload, SinkAddedByReloadWritesFromThenOn) {
  write(y4m("out.y4m") + no_png());
  start();
  reload(y4m("out.y4m") + png("png"), "reload applied: sinks.png");
  ASSERT_TRUE(frames_flow_past(result_lines() + 5)) << child_->stderr_text();
  const std::vector<nlohmann::json> results = stop();
  const std::set<uint64_t> pngs = png_indices(dir_ / "png");
  ASSERT_FALSE(pngs.empty());
  EXPECT_GT(*pngs.begin(), 0u) << "PNGs from before the reload";
  EXPECT_EQ(*pngs.rbegin(), results.size() - 1);
  EXPECT_EQ(pngs.size(), results.size() - *pngs.begin()) << "a frame after the reload has no PNG";
  EXPECT_EQ(y4m_frames(dir_ / "out.y4m"), results.size());
}

// The Y4M sink removed by a reload stops at the boundary with whole frames written and flushed;
// later frames still reach the other sinks.
TEST_F(Reload, SinkRemovedByReloadStopsAndItsFileIsComplete) {
  write(y4m("out.y4m") + no_png());
  start();
  reload(no_y4m() + no_png(), "reload applied: sinks.y4m");
  ASSERT_TRUE(child_->wait_for_stderr("sinks.y4m: closed")) << child_->stderr_text();
  const size_t written = y4m_frames(dir_ / "out.y4m");
  ASSERT_TRUE(frames_flow_past(result_lines() + 10)) << child_->stderr_text();
  EXPECT_EQ(y4m_frames(dir_ / "out.y4m"), written) << "written to after it was removed";
  const std::vector<nlohmann::json> results = stop();
  EXPECT_GE(written, 3u);
  EXPECT_GT(results.size(), written + 10);
  EXPECT_EQ(y4m_frames(dir_ / "out.y4m"), written);
}

// A Y4M sink re-pointed by a reload: the old file complete up to the boundary, the new one from the
// boundary on, each frame in exactly one of them.
TEST_F(Reload, SinkRepointedWritesToTheNewPath) {
  write(y4m("first.y4m") + no_png());
  start();
  reload(y4m("second.y4m") + no_png(), "reload applied: sinks.y4m");
  ASSERT_TRUE(frames_flow_past(result_lines() + 5)) << child_->stderr_text();
  const std::vector<nlohmann::json> results = stop();
  const size_t first = y4m_frames(dir_ / "first.y4m"), second = y4m_frames(dir_ / "second.y4m");
  EXPECT_GE(first, 3u);
  EXPECT_GE(second, 5u);
  EXPECT_EQ(first + second, results.size());
}

// light.source from "fixed" (no light stage: no light in the results) to "sun" (the light stage
// added: the sun's estimate on every frame) and back (removed again).
TEST_F(Reload, LightSourceFixedToSunAndBackIsApplied) {
  const std::string sinks = no_y4m() + no_png();
  const std::string sun =
      "[light]\nsource = \"sun\"\n[light.sun]\nlatitude_deg = 38.6444\nlongitude_deg = -9.14\n"
      "time = \"2026-03-17T10:33:37.24Z\"\n";
  write(sinks);
  start();
  reload(sinks + sun, "reload applied: light.source, light.sun");
  ASSERT_TRUE(frames_flow_past(result_lines() + 5)) << child_->stderr_text();
  reload(sinks, "reload applied: light.source, light.sun");
  ASSERT_TRUE(frames_flow_past(result_lines() + 5)) << child_->stderr_text();
  const std::vector<nlohmann::json> results = stop();
  // Three runs of frames: fixed, sun, fixed.
  std::vector<std::pair<std::string, size_t>> runs;
  for (const auto& frame : results) {
    const std::string light = frame.contains("light") ? frame["light"]["source"].get<std::string>() : "fixed";
    if (runs.empty() || runs.back().first != light) runs.emplace_back(light, 0);
    ++runs.back().second;
  }
  ASSERT_EQ(runs.size(), 3u) << child_->stderr_text();
  EXPECT_EQ(runs[0].first, "fixed");
  EXPECT_EQ(runs[1].first, "sun");
  EXPECT_GE(runs[1].second, 5u);
  EXPECT_EQ(runs[2].first, "fixed");
  EXPECT_GE(runs[2].second, 5u);
}

// A reload that changes keys needing a restart (the source, the queues) is refused whole, naming
// them: the PNG sink it also asks for is not added, and the running config goes on.
TEST_F(Reload, ChangeThatNeedsARestartIsRefusedByNameAndTheRunningConfigStays) {
  write(y4m("out.y4m") + no_png());
  start();
  const std::string changed = y4m("out.y4m") + png("png") + "[pipeline]\nqueue_depth = 8\n";
  write(changed);
  std::string text = test::read_text(config_path());
  text.replace(text.find("pacing = \"timestamps\""), 21, "pacing = \"fast\"");
  std::ofstream(config_path(), std::ios::trunc) << text;
  const size_t before = answers();
  child_->signal(SIGHUP);
  ASSERT_TRUE(child_->wait_for_stderr("reload refused")) << child_->stderr_text();
  EXPECT_EQ(answers(), before + 1);
  EXPECT_NE(child_->stderr_text().find("reload refused: source.pacing, pipeline.queue_depth need a restart; the "
                                       "running config stays"),
            std::string::npos)
      << child_->stderr_text();
  ASSERT_TRUE(frames_flow_past(result_lines() + 10)) << child_->stderr_text();
  const std::vector<nlohmann::json> results = stop();
  EXPECT_FALSE(fs::exists(dir_ / "png")) << "the refused reload added a sink";
  EXPECT_EQ(y4m_frames(dir_ / "out.y4m"), results.size());
  EXPECT_EQ(child_->stderr_text().find("reload applied"), std::string::npos) << child_->stderr_text();
}

}  // namespace
