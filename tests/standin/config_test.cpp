// The stand-in's configuration: errors name file:line:column and what was expected; a device that
// is open keeps its configuration ("busy"); symlinks to a served path are served.
#include "standin_fixture.h"

namespace arpipe::standin_test {
namespace {

class ConfigTest : public StandinTest {
 protected:
  std::string load_error(const std::string& text) {
    char error[512] = "";
    EXPECT_EQ(arpipe_v4l2_standin_load(write_config(text).c_str(), error, sizeof error), -1);
    return error;
  }
};

TEST_F(ConfigTest, UnknownKeyIsNamedWithItsPlace) {
  const std::string e = load_error("[[device]]\npath = \"/dev/video42\"\nrecording = \"" + kDefaultCapture.string() +
                                   "\"\npacing = \"fast\"\nlooping = true\n");
  EXPECT_NE(e.find("standin.toml:5:1: device[0].looping: unknown key"), std::string::npos) << e;
}

TEST_F(ConfigTest, BadValuesAreNamedWithTheirPlace) {
  const std::string rec = "recording = \"" + kDefaultCapture.string() + "\"\n";
  EXPECT_NE(load_error("[[device]]\npath = \"/dev/video42\"\n" + rec + "pacing = \"slow\"\n").find("standin.toml:4:10: device[0].pacing: expected one of"),
            std::string::npos);
  EXPECT_NE(load_error("[[device]]\npath = \"/dev/video42\"\n" + rec + "formats = [\"native\", \"H264\"]\n").find("standin.toml:4:11:"),
            std::string::npos);
  // The default capture is YUYV: "native" and "YUYV" are the same format.
  EXPECT_NE(load_error("[[device]]\npath = \"/dev/video42\"\n" + rec + "formats = [\"native\", \"YUYV\"]\n").find("twice"),
            std::string::npos);
  EXPECT_NE(load_error("[[device]]\npath = \"/dev/video42\"\n" + rec + "[[device.fault]]\nframe = 60\nkind = \"drop\"\n")
                .find("standin.toml:4:1: fault frame 60 is past the recording's last frame 59"),
            std::string::npos);
  EXPECT_NE(load_error("[[device]]\npath = \"/dev/video42\"\n" + rec + "[[device.fault]]\nframe = 1\nkind = \"stall\"\ncount = 2\n")
                .find("standin.toml:7:9: device[0].fault[0].count: applies only to"),
            std::string::npos);
  EXPECT_NE(load_error("[[device]]\npath = \"/dev/video42\"\nrecording = \"nowhere\"\n").find("standin.toml:1:1: cannot read recording"),
            std::string::npos);
  EXPECT_NE(load_error("[[device]]\nrecording = \"x\"\n").find("standin.toml:1:1: device[0].path: expected an absolute path, found nothing"), std::string::npos);
  EXPECT_NE(load_error("[[device]\n").find("standin.toml:1:"), std::string::npos);
}

TEST_F(ConfigTest, OpenDeviceKeepsItsConfiguration) {
  load("pacing = \"fast\"\n");
  const int fd = open_device();
  ASSERT_GE(fd, 0);
  char error[512] = "";
  EXPECT_EQ(arpipe_v4l2_standin_load(write_config("[[device]]\npath = \"/dev/video43\"\nrecording = \"" +
                                                  kDefaultCapture.string() + "\"\n").c_str(), error, sizeof error), -1);
  EXPECT_NE(std::string(error).find("busy"), std::string::npos) << error;
  struct arpipe_v4l2_standin_stats stats{};
  ASSERT_EQ(arpipe_v4l2_standin_stats(kDevice, &stats), 0);
  EXPECT_EQ(stats.opens, 1u);
  // Unloaded: the path is no longer served, the open fd answers ENODEV.
  arpipe_v4l2_standin_unload();
  v4l2_capability cap{};
  EXPECT_EQ(ioctl(fd, VIDIOC_QUERYCAP, &cap), -1);
  EXPECT_EQ(errno, ENODEV);
  EXPECT_EQ(arpipe_v4l2_standin_stats(kDevice, &stats), -1);
}

TEST_F(ConfigTest, SymlinkChainToTheDeviceIsServed) {
  load("pacing = \"fast\"\n");
  std::filesystem::create_directories(dir_ / "by-id");
  std::filesystem::create_symlink("/dev/video42", dir_ / "video-link");
  std::filesystem::create_symlink("../video-link", dir_ / "by-id" / "usb-arpipe-video-index0");
  const int fd = open_device(O_RDWR, (dir_ / "by-id" / "usb-arpipe-video-index0").c_str());
  ASSERT_GE(fd, 0) << strerror(errno);
  v4l2_capability cap{};
  ASSERT_EQ(ioctl(fd, VIDIOC_QUERYCAP, &cap), 0);
  EXPECT_STREQ(reinterpret_cast<const char*>(cap.driver), "arpipe-standin");
  // openat relative to a directory fd, and a path that is not served at all.
  const int dirfd = ::open(dir_.c_str(), O_RDONLY | O_DIRECTORY);
  ASSERT_GE(dirfd, 0);
  const int fd2 = openat(dirfd, "video-link", O_RDWR);
  EXPECT_GE(fd2, 0);
  if (fd2 >= 0) fds_.push_back(fd2);
  ::close(dirfd);
  EXPECT_EQ(::open("/dev/video43", O_RDWR), -1);
}

}  // namespace
}  // namespace arpipe::standin_test
