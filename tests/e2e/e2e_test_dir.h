// The fixture the daemon's end-to-end tests share: a fresh output directory per test, named after
// it under build/e2e-out/, and a private copy of the default capture for tests that damage it.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace arpipe::test {

inline const std::filesystem::path kDefaultCapture = std::filesystem::path(ARPIPE_BINARY_DIR) / "default-capture";

class E2eTestDir : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::path(ARPIPE_BINARY_DIR) / "e2e-out" /
           ::testing::UnitTest::GetInstance()->current_test_info()->name();
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  // A private copy of the default capture that a test may damage.
  std::filesystem::path copy_capture() const {
    const std::filesystem::path copy = dir_ / "capture";
    std::filesystem::copy(kDefaultCapture, copy, std::filesystem::copy_options::recursive);
    return copy;
  }

  // A config replaying `capture` as fast as it goes, whose outputs (PNGs, Y4M, results) all land
  // in this test's directory; `extra` is appended TOML.
  std::filesystem::path write_config(const std::filesystem::path& capture, const std::string& extra = "") const {
    const std::filesystem::path path = dir_ / "arpipe.toml";
    std::ofstream(path) << "[source]\npath = \"" << capture.string() << "\"\npacing = \"fast\"\n"
                        << "[sinks.png]\ndir = \"" << (dir_ / "png").string() << "\"\n"
                        << "[sinks.y4m]\npath = \"" << (dir_ / "out.y4m").string() << "\"\n"
                        << "[sinks.results]\npath = \"" << (dir_ / "results.jsonl").string() << "\"\n"
                        << extra;
    // The tests were written when a config without objects drew the default cube; they keep it
    // (objects listed in `extra` replace it, so their indices stay as written).
    if (extra.find("[[render.objects]]") == std::string::npos && extra.find("render.objects") == std::string::npos)
      std::ofstream(path, std::ios::app) << "\n[[render.objects]]\nmesh = \"builtin:cube\"\n";
    return path;
  }

  std::filesystem::path dir_;
};

}  // namespace arpipe::test
