// Debian's v4l-utils against the stand-in, preloaded into them as a user would: v4l2-ctl streams
// 60 frames whose bytes are the recording's, and v4l2-compliance finds nothing but the findings
// docs/V4L2_STANDIN.md lists (its table).
#include "standin_fixture.h"

#include <set>

#include "tests/e2e/child_process.h"

namespace arpipe::standin_test {
namespace {

const std::filesystem::path kLibrary = ARPIPE_BINARY_DIR "/tests/v4l2_standin/libarpipe-v4l2-standin.so";

class ToolsTest : public StandinTest {
 protected:
  // Runs /usr/bin/<tool> with the stand-in preloaded and `config` (a [[device]] on kDevice).
  int run_tool(const std::string& tool, const std::vector<std::string>& args, const std::string& config, std::string& out) {
    const auto path = write_config("[[device]]\npath = \"" + std::string(kDevice) + "\"\nrecording = \"" +
                                   kDefaultCapture.string() + "\"\n" + config);
    const std::vector<std::string> env = {"LD_PRELOAD=" + kLibrary.string(), "ARPIPE_V4L2_STANDIN=" + path.string()};
    test::ChildProcess child("/usr/bin/" + tool, args, dir_ / (tool + "-log"), env);
    const int status = child.wait(std::chrono::seconds(60));
    out = child.stdout_text() + child.stderr_text();
    return status == -1 ? -1000 : WIFEXITED(status) ? WEXITSTATUS(status) : -WTERMSIG(status);
  }
  void SetUp() override {
    StandinTest::SetUp();
    if (!std::filesystem::exists("/usr/bin/v4l2-ctl") || !std::filesystem::exists("/usr/bin/v4l2-compliance"))
      GTEST_SKIP() << "v4l-utils is not installed (scripts/install-deps.sh installs it)";
  }
};

TEST_F(ToolsTest, V4l2CtlStreamsSixtyFramesOfTheRecording) {
  const auto file = dir_ / "stream.raw";
  std::string out;
  ASSERT_EQ(run_tool("v4l2-ctl", {"-d", kDevice, "--stream-mmap", "--stream-count=60", "--stream-to=" + file.string()},
                     "pacing = \"fast\"\n", out), 0) << out;
  RecordingReader rec(kDefaultCapture);
  ASSERT_EQ(rec.frame_count(), 60u);
  std::ifstream in(file, std::ios::binary);
  std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  Frame frame;
  size_t at = 0;
  for (size_t i = 0; i < 60; ++i) {
    rec.read(i, frame);
    ASSERT_LE(at + frame.data.size(), bytes.size()) << "frame " << i;
    EXPECT_EQ(std::memcmp(bytes.data() + at, frame.data.data(), frame.data.size()), 0) << "frame " << i;
    at += frame.data.size();
  }
  EXPECT_EQ(at, bytes.size());
}

TEST_F(ToolsTest, V4l2CtlAllSeesACaptureDevice) {
  std::string out;
  ASSERT_EQ(run_tool("v4l2-ctl", {"-d", kDevice, "--all"}, "", out), 0) << out;
  EXPECT_NE(out.find("Driver name      : arpipe-standin"), std::string::npos) << out;
  EXPECT_NE(out.find("Pixel Format      : 'YUYV'"), std::string::npos) << out;
}

// The "test ...: FAIL" lines of a v4l2-compliance run.
std::set<std::string> failures(const std::string& out) {
  std::set<std::string> failed;
  std::istringstream lines(out);
  for (std::string line; std::getline(lines, line);)
    if (const auto end = line.rfind(": FAIL"); end != std::string::npos && line.find("test ") != std::string::npos)
      failed.insert(line.substr(line.find("test ") + 5, end - line.find("test ") - 5));
  return failed;
}

// docs/V4L2_STANDIN.md, "v4l2-compliance": priorities, and the v4l2-ctrls framework's class
// controls and range checks, which the stand-in's small control table does not have.
const std::set<std::string> kDocumentedFailures = {"VIDIOC_G/S_PRIORITY", "VIDIOC_QUERY_EXT_CTRL/QUERYMENU",
                                                   "VIDIOC_QUERYCTRL", "VIDIOC_G/S_CTRL", "VIDIOC_G/S/TRY_EXT_CTRLS"};

TEST_F(ToolsTest, V4l2ComplianceFindsOnlyTheDocumentedFailures) {
  std::string out;
  run_tool("v4l2-compliance", {"-d", kDevice, "-s"}, "pacing = \"fast\"\n", out);
  EXPECT_EQ(failures(out), kDocumentedFailures) << out;
  EXPECT_NE(out.find("Total for arpipe-standin device /dev/video42: 54, Succeeded: 49, Failed: 5, Warnings: 1"),
            std::string::npos) << out;
  for (const char* mode : {"test MMAP (no poll): OK", "test MMAP (select): OK", "test MMAP (epoll): OK"})
    EXPECT_NE(out.find(mode), std::string::npos) << mode;
}

TEST_F(ToolsTest, V4l2ComplianceOnAMultiPlanarDeviceFindsTheSame) {
  std::string out;
  run_tool("v4l2-compliance", {"-d", kDevice, "-s"},
           "pacing = \"fast\"\nbuffer_type = \"mplane\"\nformats = [\"native\", \"NV12M\", \"YUV420M\", \"NV21M\", "
           "\"NV16M\", \"UYVY\", \"YVYU\", \"NV21\", \"YU12\", \"NV16\", \"NV12\", \"RGB24\", \"GREY\", \"MJPG\"]\n",
           out);
  EXPECT_EQ(failures(out), kDocumentedFailures) << out;
  EXPECT_NE(out.find("Video Capture Multiplanar"), std::string::npos);
  EXPECT_NE(out.find("test MMAP (epoll): OK"), std::string::npos) << out;
}

}  // namespace
}  // namespace arpipe::standin_test
