// The fixture the daemon's end-to-end tests share: a fresh output directory per test, named after
// it under build/e2e-out/, and a private copy of the default capture for tests that damage it.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>

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

  std::filesystem::path dir_;
};

}  // namespace arpipe::test
