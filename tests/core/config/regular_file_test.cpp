// open_regular_file / read_regular_file: FIFOs, devices, directories, /proc and symlink loops are
// refused promptly with the path and the reason; the size limit is stated; regular files read.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <future>
#include <string>

#include "core/config/config.h"
#include "core/config/regular_file.h"

namespace arpipe {
namespace {

namespace fs = std::filesystem;

class RegularFile : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("arpipe_regular_file_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // The message of the FileAccessError that opening `path` throws, or "" when it opened.
  static std::string refusal(const fs::path& path) {
    try {
      ::close(open_regular_file(path, "test file"));
      return "";
    } catch (const FileAccessError& e) {
      return e.what();
    }
  }

  fs::path dir_;
};

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

TEST_F(RegularFile, ReadsARegularFileAndLeavesItBlocking) {
  const fs::path path = dir_ / "a.txt";
  std::ofstream(path) << "hello";
  EXPECT_EQ(read_regular_file(path, "test file", 100), "hello");
  const int fd = open_regular_file(path, "test file");
  EXPECT_EQ(::fcntl(fd, F_GETFL) & O_NONBLOCK, 0);
  ::close(fd);
}

TEST_F(RegularFile, AFifoIsRefusedWithoutBlocking) {
  const fs::path fifo = dir_ / "frames.bin";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  auto opening = std::async(std::launch::async, [&] { return refusal(fifo); });
  if (opening.wait_for(std::chrono::seconds(5)) != std::future_status::ready) {
    // Blocked in open(): a writer lets it go, so the test fails instead of hanging.
    const int writer = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
    ADD_FAILURE() << "open_regular_file blocked on a FIFO";
    opening.wait();
    if (writer >= 0) ::close(writer);
    return;
  }
  const std::string message = opening.get();
  EXPECT_TRUE(contains(message, fifo.string() + ": cannot read test file: it is a FIFO (named pipe), expected a "
                                                "regular file"))
      << message;
}

TEST_F(RegularFile, DirectoriesDevicesAndProcAreRefused) {
  EXPECT_TRUE(contains(refusal(dir_), "it is a directory, expected a regular file")) << refusal(dir_);
  EXPECT_TRUE(contains(refusal("/dev/zero"), "/dev/zero: cannot read test file: it is a character device"))
      << refusal("/dev/zero");
  EXPECT_TRUE(contains(refusal("/proc/self/environ"), "/proc/self/environ: cannot read test file: it is on /proc"))
      << refusal("/proc/self/environ");
}

TEST_F(RegularFile, ASymlinkLoopNamesThePathAndTheLoop) {
  fs::create_symlink(dir_ / "b", dir_ / "a");
  fs::create_symlink(dir_ / "a", dir_ / "b");
  const std::string message = refusal(dir_ / "a");
  EXPECT_TRUE(contains(message, (dir_ / "a").string() + ": cannot open test file: Too many levels of symbolic links"))
      << message;
}

TEST_F(RegularFile, AFileOverTheLimitIsRefusedWithTheLimit) {
  const fs::path path = dir_ / "big.txt";
  std::ofstream(path) << std::string(100, 'x');
  try {
    read_regular_file(path, "test file", 10);
    ADD_FAILURE() << "expected a FileAccessError";
  } catch (const FileAccessError& e) {
    EXPECT_EQ(std::string(e.what()), path.string() + ": cannot read test file: it is larger than the limit of 10 bytes");
    EXPECT_EQ(e.reason(), "it is larger than the limit of 10 bytes");
  }
  EXPECT_EQ(read_regular_file(path, "test file", 100).size(), 100u);
}

// The config loader goes through it: a FIFO config fails at once, a loop is named, not a raw
// std::filesystem message.
TEST_F(RegularFile, ConfigFilesAreRegularFilesOnly) {
  const fs::path fifo = dir_ / "arpiped.toml";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  auto loading = std::async(std::launch::async, [&]() -> std::string {
    try {
      load_config(fifo);
      return "";
    } catch (const ConfigError& e) {
      return e.what();
    }
  });
  if (loading.wait_for(std::chrono::seconds(5)) != std::future_status::ready) {
    const int writer = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
    ADD_FAILURE() << "load_config blocked on a FIFO";
    loading.wait();
    if (writer >= 0) ::close(writer);
    return;
  }
  EXPECT_EQ(loading.get(),
            fifo.string() + ": cannot read config: it is a FIFO (named pipe), expected a regular file");

  fs::create_symlink(dir_ / "loop2.toml", dir_ / "loop1.toml");
  fs::create_symlink(dir_ / "loop1.toml", dir_ / "loop2.toml");
  try {
    load_config(dir_ / "loop1.toml");
    ADD_FAILURE() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()),
              (dir_ / "loop1.toml").string() + ": cannot read config: Too many levels of symbolic links");
  }
}

}  // namespace
}  // namespace arpipe
