// The real arpiped keeps its outputs valid and itself running (issue 18): a start that fails leaves
// the previous run's outputs as they were (finding 5); a full disk that is freed again loses whole
// lines, frames and PNGs only, logged once each way (finding 6, the 3 MB tmpfs check); a
// Y4M reader that leaves ends nothing (finding 7); a recording is never overwritten (finding 10).
#include <fcntl.h>
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <sched.h>
#include <sys/mount.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <thread>

#include "capture/recording/recording_reader.h"
#include "capture/recording/recording_writer.h"
#include "core/image/pixel_convert.h"
#include "tests/e2e/child_process.h"

namespace fs = std::filesystem;
using namespace arpipe;
using namespace std::chrono_literals;

namespace {

const fs::path kCapture = fs::path(ARPIPE_BINARY_DIR) / "default-capture";
const fs::path kConfig = fs::path(ARPIPE_SOURCE_DIR) / "configs" / "arpipe.toml";

size_t occurrences(std::string_view text, std::string_view needle) {
  size_t n = 0;
  for (size_t at = text.find(needle); at != std::string_view::npos; at = text.find(needle, at + 1)) ++n;
  return n;
}

std::string read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Names in dir that start with '.': temporaries a sink left behind.
std::vector<std::string> hidden_files(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::recursive_directory_iterator(dir))
    if (entry.path().filename().string().starts_with(".")) names.push_back(entry.path().string());
  return names;
}

// Indices of the lines of a results file, each of which must parse as JSON.
std::vector<uint64_t> result_indices(const fs::path& file) {
  std::vector<uint64_t> indices;
  std::ifstream in(file);
  size_t number = 0;
  for (std::string line; std::getline(in, line);) {
    ++number;
    try {
      indices.push_back(nlohmann::json::parse(line).at("index").get<uint64_t>());
    } catch (const std::exception& e) {
      ADD_FAILURE() << file << " line " << number << " is not a whole results line (" << e.what() << "): " << line;
    }
  }
  return indices;
}

struct Y4mCheck {
  size_t frames = 0;
  size_t torn_tail_bytes = 0;
  bool markers_ok = true;
  std::string header;
};

Y4mCheck check_y4m(const fs::path& file, int width, int height) {
  const std::string bytes = read_bytes(file);
  Y4mCheck out;
  const size_t header_end = bytes.find('\n');
  if (header_end == std::string::npos) {
    out.torn_tail_bytes = bytes.size();
    return out;
  }
  out.header = bytes.substr(0, header_end);
  const size_t payload = size_t(width) * size_t(height) * 3 / 2;
  size_t at = header_end + 1;
  for (; at + 6 + payload <= bytes.size(); at += 6 + payload, ++out.frames)
    if (bytes.compare(at, 6, "FRAME\n") != 0) out.markers_ok = false;
  out.torn_tail_bytes = bytes.size() - at;
  return out;
}

class OutputsSurvive : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(ARPIPE_BINARY_DIR) / "e2e-out" /
           (std::string("outputs-") + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    ASSERT_TRUE(fs::exists(kCapture / "recording.json")) << "the build generates " << kCapture;
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }
  // arpiped over a capture (pacing fast), outputs named by `sets` ("key=value" TOML overrides).
  std::vector<std::string> args(const fs::path& capture, const std::vector<std::string>& sets) const {
    std::vector<std::string> a{"--config", kConfig.string(), "--set", "source.path=\"" + capture.string() + "\""};
    for (const auto& s : sets) a.insert(a.end(), {"--set", s});
    return a;
  }
  static std::string quoted(const fs::path& path) { return "\"" + path.string() + "\""; }
  fs::path dir_;
};

// ---------------------------------------------------------------------------------------------
// Finding 5: a start that fails leaves the previous run's results.jsonl and video as they were:
// a mesh that does not parse (found while the stages are configured), and a recording sink onto
// an existing recording (found when the outputs are opened, after the results and video sinks).
TEST_F(OutputsSurvive, AFailedStartLeavesThePreviousRunsOutputsUntouched) {
  const fs::path out = dir_ / "out";
  const std::vector<std::string> outputs = {
      "sinks.results.path=" + quoted(out / "results.jsonl"), "sinks.y4m.path=" + quoted(out / "arpiped.y4m"),
      "sinks.png.enabled=false", "sinks.recording.path=" + quoted(out / "composited"), "source.pacing=\"fast\"",
      "pipeline.max_frames=5"};
  std::vector<std::string> first = outputs;
  first.push_back("sinks.recording.enabled=true");
  std::string err;
  ASSERT_EQ(test::run_to_exit(test::build_program("arpiped"), args(kCapture, first), dir_ / "logs-good", &err), 0)
      << err;
  const std::string results = read_bytes(out / "results.jsonl");
  const std::string video = read_bytes(out / "arpiped.y4m");
  ASSERT_EQ(occurrences(results, "\n"), 5u);
  ASSERT_GT(video.size(), 5u * 640 * 480 * 3 / 2);

  std::ofstream(dir_ / "broken.gltf") << "{ \"asset\": { \"version\": \"2.0\" }, \"meshes\": [ {";  // cut off
  std::vector<std::string> bad_mesh = outputs;
  bad_mesh.push_back("render.objects.0.mesh=" + quoted(dir_ / "broken.gltf"));
  EXPECT_EQ(test::run_to_exit(test::build_program("arpiped"), args(kCapture, bad_mesh), dir_ / "logs-mesh", &err), 2)
      << err;
  EXPECT_NE(err.find("broken.gltf"), std::string::npos) << err;
  EXPECT_TRUE(read_bytes(out / "results.jsonl") == results) << "the failed start changed results.jsonl";
  EXPECT_TRUE(read_bytes(out / "arpiped.y4m") == video) << "the failed start changed the video";

  EXPECT_EQ(test::run_to_exit(test::build_program("arpiped"), args(kCapture, first), dir_ / "logs-recording", &err), 2)
      << err;
  EXPECT_NE(err.find("sinks.recording.path"), std::string::npos) << err;
  EXPECT_TRUE(read_bytes(out / "results.jsonl") == results) << "the failed start changed results.jsonl";
  EXPECT_TRUE(read_bytes(out / "arpiped.y4m") == video) << "the failed start changed the video";
  EXPECT_EQ(hidden_files(out), std::vector<std::string>{}) << "temporaries left behind";
}

// ---------------------------------------------------------------------------------------------
// Finding 7: the Y4M goes to a FIFO whose reader takes a frame and quits. arpiped logs the broken
// pipe once and goes on; the next player to open the FIFO gets a stream of its own, header first;
// SIGTERM ends the run as usual (exit 0) with the results whole.

// Reads from a non-blocking FIFO reader until `wanted` bytes came (or 30 s passed).
std::string read_fifo(int reader, size_t wanted) {
  std::string received;
  const auto deadline = std::chrono::steady_clock::now() + 30s;
  while (received.size() < wanted && std::chrono::steady_clock::now() < deadline) {
    pollfd p{reader, POLLIN, 0};
    if (poll(&p, 1, 100) <= 0) continue;
    char buffer[65536];
    const ssize_t n = ::read(reader, buffer, sizeof buffer);
    if (n > 0) received.append(buffer, size_t(n));
    else if (n == 0) std::this_thread::sleep_for(10ms);  // no writer (yet)
  }
  return received;
}

TEST_F(OutputsSurvive, AY4mReaderThatQuitsEndsNeitherTheDaemonNorTheOtherOutputs) {
  const fs::path fifo = dir_ / "video.y4m";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0) << std::strerror(errno);
  RecordingReader capture(kCapture);
  const std::string header = fmt::format("YUV4MPEG2 W{} H{}", capture.info().width, capture.info().height);
  const size_t frame_bytes = 6 + size_t(capture.info().width) * capture.info().height * 3 / 2;
  // Opened before arpiped, without blocking, so its own (blocking) open finds a reader; not
  // inherited by arpiped, whose copy would keep the FIFO open for reading after this one quits.
  const int first_reader = ::open(fifo.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  ASSERT_GE(first_reader, 0);

  test::ChildProcess child(test::build_program("arpiped"),
                           args(kCapture, {"sinks.y4m.path=" + quoted(fifo),
                                           "sinks.results.path=" + quoted(dir_ / "results.jsonl"),
                                           "sinks.png.enabled=false", "source.pacing=\"timestamps\"",
                                           "source.loop=true"}),
                           dir_ / "logs");
  const std::string first = read_fifo(first_reader, header.size() + frame_bytes);
  ::close(first_reader);  // the player quits
  EXPECT_TRUE(first.starts_with(header)) << first.substr(0, 80);
  ASSERT_TRUE(child.wait_for_stderr(fifo.string() + ": cannot write frame")) << child.stderr_text();

  const int second_reader = ::open(fifo.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);  // another player
  ASSERT_GE(second_reader, 0);
  const std::string second = read_fifo(second_reader, 64 + frame_bytes);
  ::close(second_reader);
  EXPECT_TRUE(second.starts_with(header)) << "the next reader's stream starts with " << second.substr(0, 80);
  EXPECT_EQ(second.compare(second.find('\n') + 1, 6, "FRAME\n"), 0);

  child.signal(SIGTERM);
  const int status = child.wait(60s);
  ASSERT_NE(status, -1) << "arpiped did not finish: " << child.stderr_text();
  ASSERT_TRUE(WIFEXITED(status)) << "arpiped died of signal " << WTERMSIG(status) << ": " << child.stderr_text();
  EXPECT_EQ(WEXITSTATUS(status), 0) << child.stderr_text();
  const std::string log = child.stderr_text();
  // Two readers quit, within a minute: the first broken pipe is logged, the second only counted.
  EXPECT_EQ(occurrences(log, fifo.string() + ": cannot write frame"), 1u) << log;
  EXPECT_NE(log.find(std::strerror(EPIPE)), std::string::npos) << log;
  EXPECT_EQ(occurrences(log, fifo.string() + ": writing resumed"), 1u) << log;
  EXPECT_GT(result_indices(dir_ / "results.jsonl").size(), 0u);
}

// ---------------------------------------------------------------------------------------------
// Finding 10: a second run onto the first run's recording fails setup, naming the path and key.
TEST_F(OutputsSurvive, StartingOntoAnExistingRecordingFailsSetup) {
  const fs::path recording = dir_ / "composited";
  const std::vector<std::string> sets = {"sinks.recording.enabled=true", "sinks.recording.path=" + quoted(recording),
                                         "sinks.results.enabled=false", "sinks.y4m.enabled=false",
                                         "sinks.png.enabled=false", "source.pacing=\"fast\"", "pipeline.max_frames=3"};
  std::string err;
  ASSERT_EQ(test::run_to_exit(test::build_program("arpiped"), args(kCapture, sets), dir_ / "logs-first", &err), 0)
      << err;
  const std::string metadata = read_bytes(recording / "frames.jsonl");
  ASSERT_EQ(RecordingReader(recording).frame_count(), 3u);

  EXPECT_EQ(test::run_to_exit(test::build_program("arpiped"), args(kCapture, sets), dir_ / "logs-second", &err), 2)
      << err;
  EXPECT_NE(err.find(recording.string() + " (config sinks.recording.path): already holds a recording"),
            std::string::npos)
      << err;
  EXPECT_EQ(read_bytes(recording / "frames.jsonl"), metadata);
}

// ---------------------------------------------------------------------------------------------
// The acceptance check: the outputs live on a 3 MB tmpfs that fills up mid-run (a filler
// file takes all the room left) and is freed again. Every results line parses, the Y4M holds
// whole frames only, every PNG decodes, arpiped runs to the end, and the log says once per output
// what happened and once that writing resumed.
//
// 640x480 frames (460 KB in the Y4M each) would fill 3 MB by themselves in 7 frames, so the run
// replays the default capture scaled down 4x (160x120, lens model scaled to match) at 10 frames a
// second: 60 frames in 6 s, about 2 MB of outputs.

// Mounts a tmpfs of `size` at dir in a mount namespace of this process (and of the children it
// starts) only: as root, or else as root of a new user namespace. Empty when it could, else why not.
std::string mount_private_tmpfs(const fs::path& dir, const std::string& size) {
  const std::string options = "size=" + size;
  std::string why;
  if (unshare(CLONE_NEWNS) != 0) {
    why = fmt::format("unshare(CLONE_NEWNS): {}", std::strerror(errno));
    const uid_t uid = getuid();
    const gid_t gid = getgid();
    if (unshare(CLONE_NEWUSER | CLONE_NEWNS) != 0)
      return why + fmt::format("; unshare(CLONE_NEWUSER | CLONE_NEWNS): {}", std::strerror(errno));
    std::ofstream("/proc/self/setgroups") << "deny";
    std::ofstream("/proc/self/uid_map") << fmt::format("0 {} 1", uid);
    std::ofstream("/proc/self/gid_map") << fmt::format("0 {} 1", gid);
  }
  // Mounts made here stay in this namespace.
  if (mount("none", "/", nullptr, MS_REC | MS_PRIVATE, nullptr) != 0)
    return fmt::format("making / private: {}", std::strerror(errno));
  if (mount("tmpfs", dir.c_str(), "tmpfs", 0, options.c_str()) != 0)
    return fmt::format("mount -t tmpfs -o {} {}: {}", options, dir.string(), std::strerror(errno));
  return {};
}

// The default capture at a quarter of its size (RGB24), one frame every 100 ms.
void write_small_capture(const fs::path& out, int factor) {
  RecordingReader reader(kCapture);
  const CameraModel& model = reader.camera_model();
  std::vector<double> intrinsics = model.intrinsics();
  // Pixel centres: new pixel u covers old pixels factor*u .. factor*u + factor-1.
  const double scale = 1.0 / factor;
  intrinsics[0] *= scale;
  intrinsics[1] *= scale;
  intrinsics[2] = (intrinsics[2] - (factor - 1) / 2.0) * scale;
  intrinsics[3] = (intrinsics[3] - (factor - 1) / 2.0) * scale;
  const int width = reader.info().width / factor, height = reader.info().height / factor;
  RecordingInfo info;
  info.pixel_format = PixelFormat::RGB24;
  info.width = width;
  info.height = height;
  info.source = "default capture scaled down for the tmpfs test";
  RecordingWriter writer(out, info, CameraModel(model.lensmodel(), intrinsics, width, height));
  const int64_t start_ns = reader.metadata(0).exposure_start_ns;
  constexpr int64_t kIntervalNs = 100'000'000;
  for (size_t i = 0; i < reader.frame_count(); ++i) {
    Frame frame;
    reader.read(i, frame);
    std::vector<uint8_t> rgb;
    to_rgb24(frame, rgb);
    cv::Mat small;
    cv::resize(cv::Mat(frame.height, frame.width, CV_8UC3, rgb.data()), small, cv::Size(width, height), 0, 0,
               cv::INTER_AREA);
    Frame out_frame;
    out_frame.format = PixelFormat::RGB24;
    out_frame.width = width;
    out_frame.height = height;
    out_frame.bytes_per_line = writer.info().bytes_per_line;
    out_frame.data.assign(small.data, small.data + small.total() * small.elemSize());
    out_frame.meta = frame.meta;
    out_frame.meta.exposure_start_ns = start_ns + int64_t(i) * kIntervalNs;
    out_frame.meta.frame_duration_ns = kIntervalNs;
    writer.append(out_frame);
  }
  writer.flush();
}

TEST_F(OutputsSurvive, A3MbTmpfsThatFillsAndIsFreedLosesOnlyWholeLinesFramesAndPngs) {
  constexpr int kFactor = 4;
  const fs::path capture = dir_ / "small-capture";
  write_small_capture(capture, kFactor);
  RecordingReader small(capture);
  const int width = small.info().width, height = small.info().height;

  const fs::path disk = dir_ / "tmpfs";
  fs::create_directories(disk);
  if (const std::string why = mount_private_tmpfs(disk, "3m"); !why.empty())
    GTEST_SKIP() << "no private tmpfs for the full-disk check: " << why;
  struct Unmount {
    fs::path dir;
    ~Unmount() { umount2(dir.c_str(), MNT_DETACH); }
  } unmount{disk};

  const fs::path results = disk / "results.jsonl", video = disk / "arpiped.y4m", png = disk / "png";
  test::ChildProcess child(
      test::build_program("arpiped"),
      args(capture, {"sinks.results.path=" + quoted(results), "sinks.y4m.path=" + quoted(video),
                     "sinks.png.dir=" + quoted(png), "sinks.png.every=3", "source.pacing=\"timestamps\""}),
      dir_ / "logs");  // the log is not on the small disk

  // Frames are flowing: fill the disk.
  const auto deadline = std::chrono::steady_clock::now() + 30s;
  while (test::count_lines(results) < 8 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(20ms);
  ASSERT_GE(test::count_lines(results), 8u) << child.stderr_text();
  // The filler takes every page left, and keeps taking the pages a sink gives back when it cuts a
  // partial write back, until every output has met the full disk and a few more frames went by.
  const fs::path filler = disk / "filler";
  const int fd = ::open(filler.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
  ASSERT_GE(fd, 0);
  const auto fill = [fd] {
    static const std::vector<char> block(4096, 'f');
    while (::write(fd, block.data(), block.size()) > 0) {
    }
    return errno;
  };
  EXPECT_EQ(fill(), ENOSPC);
  const auto all_failed = [&] {
    const std::string log = child.stderr_text();
    for (const fs::path& target : {results, video, png})
      if (log.find(target.string() + ": cannot write frame") == std::string::npos) return false;
    return true;
  };
  const auto fill_deadline = std::chrono::steady_clock::now() + 20s;
  while (!all_failed() && std::chrono::steady_clock::now() < fill_deadline) {
    fill();
    std::this_thread::sleep_for(5ms);
  }
  EXPECT_TRUE(all_failed()) << "not every output met the full disk: " << child.stderr_text();
  for (const auto until = std::chrono::steady_clock::now() + 500ms; std::chrono::steady_clock::now() < until;) {
    fill();
    std::this_thread::sleep_for(5ms);
  }
  // Space returns.
  ::close(fd);
  fs::remove(filler);

  const int status = child.wait(60s);
  ASSERT_NE(status, -1) << "arpiped did not finish: " << child.stderr_text();
  ASSERT_TRUE(WIFEXITED(status)) << "arpiped died of signal " << WTERMSIG(status) << ": " << child.stderr_text();
  EXPECT_EQ(WEXITSTATUS(status), 0) << child.stderr_text();
  const std::string log = child.stderr_text();

  // Whole lines, in order, with a gap where the disk was full, up to the last frame.
  const auto indices = result_indices(results);
  ASSERT_FALSE(indices.empty());
  EXPECT_LT(indices.size(), small.frame_count()) << "the disk never filled";
  EXPECT_EQ(indices.back(), small.frame_count() - 1) << "writing did not resume";
  for (size_t k = 1; k < indices.size(); ++k) EXPECT_LT(indices[k - 1], indices[k]);

  const Y4mCheck y4m = check_y4m(video, width, height);
  EXPECT_TRUE(y4m.header.starts_with(fmt::format("YUV4MPEG2 W{} H{} F10:1", width, height))) << y4m.header;
  EXPECT_TRUE(y4m.markers_ok);
  EXPECT_EQ(y4m.torn_tail_bytes, 0u) << "a partial frame";
  EXPECT_GT(y4m.frames, 8u);
  EXPECT_LT(y4m.frames, small.frame_count());

  size_t pngs = 0;
  for (const auto& entry : fs::directory_iterator(png)) {
    const cv::Mat image = cv::imread(entry.path().string(), cv::IMREAD_UNCHANGED);
    EXPECT_FALSE(image.empty()) << entry.path() << " does not decode";
    EXPECT_EQ(image.cols, width) << entry.path();
    ++pngs;
  }
  EXPECT_GT(pngs, 2u);
  EXPECT_LT(pngs, (small.frame_count() + 2) / 3);
  EXPECT_EQ(hidden_files(disk), std::vector<std::string>{});

  for (const fs::path& target : {results, video, png}) {
    EXPECT_EQ(occurrences(log, target.string() + ": cannot write frame"), 1u) << target << ":\n" << log;
    EXPECT_EQ(occurrences(log, target.string() + ": writing resumed"), 1u) << target << ":\n" << log;
  }
  EXPECT_NE(log.find(std::strerror(ENOSPC)), std::string::npos) << log;
}

}  // namespace
