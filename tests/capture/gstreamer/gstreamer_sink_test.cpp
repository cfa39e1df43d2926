// The GStreamer sink through real pipelines: raw bytes to a file (byte-exact, rows with and without
// GStreamer's stride), Matroska read back by ffprobe and ffmpeg (every frame, in order, at its
// exposure's time), an RTSP round trip to a gst-rtsp-server on loopback, a pipeline that stops
// taking frames, and pipelines that cannot work refused at start by name.
#include <fmt/format.h>
#include <gst/app/gstappsink.h>
#include <gst/rtp/gstrtpbuffer.h>
#include <gst/rtsp-server/rtsp-server.h>
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>
#include <thread>

#include "capture/sinks/gstreamer/gst_handles.h"
#include "capture/sinks/gstreamer/gstreamer_sink.h"

namespace arpipe {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

constexpr int64_t kFirstExposureNs = 5'000'000'000;

// Exposure starts of the test frames: 30 frames/s with a jitter of a few ms, as a camera has.
int64_t exposure_of(uint64_t index) { return kFirstExposureNs + int64_t(index) * 33'333'333 + int64_t(index % 3) * 2'000'000; }

std::shared_ptr<const FrameContext> frame(uint64_t index, int width, int height) {
  auto ctx = std::make_shared<FrameContext>();
  ctx->input_index = index;
  ctx->output = Frame::allocate(PixelFormat::RGB24, width, height);
  ctx->output.meta.sequence = index;
  ctx->output.meta.exposure_start_ns = exposure_of(index);
  ctx->output.meta.frame_duration_ns = 33'333'333;
  ctx->camera.meta = ctx->output.meta;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width * 3; ++x)
      ctx->output.data[size_t(y) * ctx->output.bytes_per_line + size_t(x)] = uint8_t((x * 7 + y * 13 + index * 29) & 0xff);
  return ctx;
}

// The frame's pixels without row padding.
std::string packed(const Frame& f) {
  std::string out;
  for (int y = 0; y < f.height; ++y)
    out.append(reinterpret_cast<const char*>(f.data.data() + size_t(y) * f.bytes_per_line), size_t(f.width) * 3);
  return out;
}

std::string read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::string run_command(const std::string& command) {
  std::string out;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return out;
  char buffer[4096];
  while (size_t n = std::fread(buffer, 1, sizeof buffer, pipe)) out.append(buffer, n);
  pclose(pipe);
  return out;
}

fs::path test_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / fmt::format("arpipe-gst-{}-{}", name, ::getpid());
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

GstreamerSinkConfig pipeline(std::string text) {
  GstreamerSinkConfig config;
  config.enabled = true;
  config.pipeline = std::move(text);
  return config;
}

// Raw RGB to a file: the bytes are the frames' pixels, in order, none lost, whether the frame's rows
// have GStreamer's stride (640: zero copy) or not (a 4-byte-padded stride for 322 px: copied).
TEST(GstreamerSink, RawFramesReachAFileByteExact) {
  for (const auto& [width, height, copies] : {std::tuple{640, 48, false}, std::tuple{322, 40, true}}) {
    const fs::path dir = test_dir("raw");
    const fs::path file = dir / "frames.rgb";
    std::string expected;
    {
      GstreamerSink sink(pipeline("appsrc name=arpipe ! filesink location=" + file.string()));
      sink.run_started();
      for (uint64_t i = 0; i < 20; ++i) {
        auto ctx = frame(i, width, height);
        expected += packed(ctx->output);
        sink.consume_shared(ctx);
      }
      sink.flush();
      EXPECT_EQ(sink.frames_pushed(), 20u);
      EXPECT_EQ(sink.failures(), 0u);
      EXPECT_EQ(sink.frames_copied(), copies ? 20u : 0u) << width;
    }
    const std::string written = read_bytes(file);
    if (!copies) {
      EXPECT_TRUE(written == expected) << width << ": " << written.size() << " bytes, expected " << expected.size();
    } else {
      // GStreamer's RGB rows are padded to 4 bytes: 322 * 3 = 966 -> 968.
      const size_t stride = 968, row = size_t(width) * 3;
      ASSERT_EQ(written.size(), stride * size_t(height) * 20);
      std::string unpadded;
      for (size_t r = 0; r < size_t(height) * 20; ++r) unpadded += written.substr(r * stride, row);
      EXPECT_TRUE(unpadded == expected);
    }
    fs::remove_all(dir);
  }
}

// Matroska with raw video, read back by FFmpeg: every frame, in order, at its exposure's time from
// the first (Matroska keeps milliseconds), and the same pixels.
TEST(GstreamerSink, MatroskaReadBackByFfprobeHasEveryFrameAtItsExposureTime) {
  if (std::system("command -v ffprobe > /dev/null 2>&1") != 0) GTEST_SKIP() << "ffprobe is not installed";
  const fs::path dir = test_dir("mkv");
  const fs::path file = dir / "out.mkv";
  constexpr int kFrames = 30, kWidth = 160, kHeight = 120;
  std::string expected;
  {
    GstreamerSink sink(pipeline("appsrc name=arpipe ! matroskamux ! filesink location=" + file.string()));
    for (uint64_t i = 0; i < kFrames; ++i) {
      auto ctx = frame(i, kWidth, kHeight);
      expected += packed(ctx->output);
      sink.consume_shared(ctx);
    }
    sink.flush();
  }
  const std::string times = run_command("ffprobe -v error -select_streams v:0 -show_entries frame=pts_time -of csv=p=0 " + file.string());
  std::istringstream lines(times);
  int n = 0;
  for (std::string line; std::getline(lines, line); ++n) {
    ASSERT_LT(n, kFrames);
    const double expected_s = double(exposure_of(uint64_t(n)) - kFirstExposureNs) * 1e-9;
    EXPECT_NEAR(std::stod(line), expected_s, 0.0006) << "frame " << n;  // Matroska: 1 ms ticks
  }
  EXPECT_EQ(n, kFrames);
  const fs::path decoded = dir / "decoded.rgb";
  ASSERT_EQ(std::system(("ffmpeg -v error -i " + file.string() + " -f rawvideo -pix_fmt rgb24 " + decoded.string()).c_str()), 0);
  EXPECT_TRUE(read_bytes(decoded) == expected);
  fs::remove_all(dir);
}

// A receiving RTSP server (gst-rtsp-server, RECORD mode) on loopback, as mediamtx would be, with its
// own main loop; what arrives is collected.
class RtspReceiver {
 public:
  RtspReceiver() : context_(g_main_context_new()), loop_(g_main_loop_new(context_, FALSE)), server_(gst_rtsp_server_new()) {
    gst_rtsp_server_set_address(server_, "127.0.0.1");
    gst_rtsp_server_set_service(server_, "0");
    GstRTSPMountPoints* mounts = gst_rtsp_server_get_mount_points(server_);
    GstRTSPMediaFactory* factory = gst_rtsp_media_factory_new();
    gst_rtsp_media_factory_set_transport_mode(factory, GST_RTSP_TRANSPORT_MODE_RECORD);
    // identity first, to read the RTP timestamps as they arrived (the receiver's own buffer times
    // are re-made from arrival by its jitter buffer).
    gst_rtsp_media_factory_set_launch(factory, "( identity name=depay0 ! rtpvrawdepay ! appsink name=received sync=false )");
    g_signal_connect(factory, "media-constructed", G_CALLBACK(&RtspReceiver::constructed), this);
    gst_rtsp_mount_points_add_factory(mounts, "/arpipe", factory);
    g_object_unref(mounts);
    source_id_ = gst_rtsp_server_attach(server_, context_);
    thread_ = std::thread([this] { g_main_loop_run(loop_); });
  }
  ~RtspReceiver() {
    g_main_loop_quit(loop_);
    thread_.join();
    if (source_id_) {
      if (GSource* source = g_main_context_find_source_by_id(context_, source_id_)) g_source_destroy(source);
    }
    g_object_unref(server_);
    g_main_loop_unref(loop_);
    g_main_context_unref(context_);
  }
  std::string url() const { return fmt::format("rtsp://127.0.0.1:{}/arpipe", gst_rtsp_server_get_bound_port(server_)); }
  std::vector<std::string> received() {
    std::lock_guard lock(mutex_);
    return received_;
  }
  // The RTP timestamp (90 kHz) of each frame as it arrived, in order of arrival.
  std::vector<uint32_t> rtp_times() {
    std::lock_guard lock(mutex_);
    return rtp_times_;
  }

 private:
  static void constructed(GstRTSPMediaFactory*, GstRTSPMedia* media, gpointer self) {
    GstElement* element = gst_rtsp_media_get_element(media);
    GstElement* sink = gst_bin_get_by_name(GST_BIN(element), "received");
    GstAppSinkCallbacks callbacks{};
    callbacks.new_sample = &RtspReceiver::on_sample;
    gst_app_sink_set_callbacks(GST_APP_SINK(sink), &callbacks, self, nullptr);
    gst_object_unref(sink);
    GstElement* identity = gst_bin_get_by_name(GST_BIN(element), "depay0");
    GstPad* pad = gst_element_get_static_pad(identity, "src");
    gst_pad_add_probe(pad, GST_PAD_PROBE_TYPE_BUFFER, &RtspReceiver::on_rtp, self, nullptr);
    gst_object_unref(pad);
    gst_object_unref(identity);
    gst_object_unref(element);
  }
  static GstPadProbeReturn on_rtp(GstPad*, GstPadProbeInfo* info, gpointer self_pointer) {
    auto* self = static_cast<RtspReceiver*>(self_pointer);
    GstRTPBuffer rtp = GST_RTP_BUFFER_INIT;
    if (gst_rtp_buffer_map(GST_PAD_PROBE_INFO_BUFFER(info), GST_MAP_READ, &rtp)) {
      const uint32_t time = gst_rtp_buffer_get_timestamp(&rtp);
      std::lock_guard lock(self->mutex_);
      if (self->rtp_times_.empty() || self->rtp_times_.back() != time) self->rtp_times_.push_back(time);
      gst_rtp_buffer_unmap(&rtp);
    }
    return GST_PAD_PROBE_OK;
  }
  static GstFlowReturn on_sample(GstAppSink* sink, gpointer self_pointer) {
    auto* self = static_cast<RtspReceiver*>(self_pointer);
    GstSample* sample = gst_app_sink_pull_sample(sink);
    if (!sample) return GST_FLOW_EOS;
    GstBuffer* buffer = gst_sample_get_buffer(sample);
    GstMapInfo map;
    if (gst_buffer_map(buffer, &map, GST_MAP_READ)) {
      std::lock_guard lock(self->mutex_);
      self->received_.emplace_back(reinterpret_cast<const char*>(map.data), map.size);
      gst_buffer_unmap(buffer, &map);
    }
    gst_sample_unref(sample);
    return GST_FLOW_OK;
  }

  GMainContext* context_;
  GMainLoop* loop_;
  GstRTSPServer* server_;
  guint source_id_ = 0;
  std::thread thread_;
  std::mutex mutex_;
  std::vector<std::string> received_;
  std::vector<uint32_t> rtp_times_;
};

// rtspclientsink over TCP to the receiver: every frame arrives, byte-exact (raw RGB payload), in
// order, its RTP timestamp from the first within one 90 kHz tick of its exposure's.
TEST(GstreamerSink, RtspRoundTripOnLoopbackDeliversEveryFrame) {
  ensure_gstreamer_initialised();
  RtspReceiver receiver;
  constexpr int kFrames = 15, kWidth = 64, kHeight = 48;
  std::vector<std::string> sent;
  {
    GstreamerSink sink(pipeline("appsrc name=arpipe ! rtspclientsink protocols=tcp latency=0 location=" + receiver.url()));
    for (uint64_t i = 0; i < kFrames; ++i) {
      auto ctx = frame(i, kWidth, kHeight);
      sent.push_back(packed(ctx->output));
      sink.consume_shared(ctx);
    }
    // Every frame arrives while the stream is up (the end of the stream tears the session down,
    // and a loaded machine may not have passed the last frame through the receiver by then).
    for (int i = 0; i < 500 && receiver.received().size() < size_t(kFrames); ++i) std::this_thread::sleep_for(20ms);
    sink.flush();
    EXPECT_EQ(sink.failures(), 0u);
  }
  const std::vector<std::string> got = receiver.received();
  for (size_t i = 0; i < std::min(got.size(), sent.size()); ++i)
    if (got[i] != sent[i]) ADD_FAILURE() << "received frame " << i << " differs from frame " << i << " sent";
  ASSERT_EQ(got.size(), size_t(kFrames));
  const std::vector<uint32_t> times = receiver.rtp_times();
  ASSERT_EQ(times.size(), size_t(kFrames));
  for (size_t i = 0; i < times.size(); ++i) {
    const double ticks = double(uint32_t(times[i] - times[0]));  // wraps like RTP's clock
    EXPECT_NEAR(ticks, double(exposure_of(i) - kFirstExposureNs) * 90e3 * 1e-9, 1.0) << "frame " << i;
  }
}

// A pipeline that stops taking frames (one buffer a second downstream) holds the sink at most
// eos_timeout_ms per frame: the frame is counted as lost, the sink goes on, and it ends.
// A TCP listener on loopback that collects what connects to it (a stand-in for a network receiver
// that goes away and comes back), on a port fixed across its restarts.
class TcpReceiver {
 public:
  explicit TcpReceiver(uint16_t port = 0) {
    listen_fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    const int one = 1;
    ::setsockopt(listen_fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    address.sin_port = htons(port);
    if (::bind(listen_fd_, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0 || ::listen(listen_fd_, 4) != 0) {
      ADD_FAILURE() << "cannot listen on 127.0.0.1:" << port << ": " << std::strerror(errno);
      return;
    }
    socklen_t length = sizeof address;
    ::getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&address), &length);
    port_ = ntohs(address.sin_port);
    thread_ = std::thread([this] {
      pollfd fds{listen_fd_, POLLIN, 0};
      if (::poll(&fds, 1, 10'000) != 1) return;  // bounded: a sink that never connects fails the test
      const int client = ::accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC);
      if (client < 0) return;
      client_fd_ = client;
      char chunk[65536];
      for (;;) {
        pollfd in{client, POLLIN, 0};
        if (::poll(&in, 1, 200) == 0) {
          if (stop_) break;
          continue;
        }
        const ssize_t n = ::recv(client, chunk, sizeof chunk, 0);
        if (n <= 0) break;
        std::lock_guard lock(mutex_);
        bytes_.append(chunk, size_t(n));
      }
    });
  }
  ~TcpReceiver() { close(); }
  // Goes away: the connection and the listening socket closed (the sender's next writes fail).
  void close() {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
    if (client_fd_ >= 0) ::close(client_fd_);
    if (listen_fd_ >= 0) ::close(listen_fd_);
    client_fd_ = listen_fd_ = -1;
  }
  uint16_t port() const { return port_; }
  std::string bytes() {
    std::lock_guard lock(mutex_);
    return bytes_;
  }

 private:
  int listen_fd_ = -1;
  int client_fd_ = -1;
  uint16_t port_ = 0;
  std::atomic<bool> stop_{false};
  std::thread thread_;
  std::mutex mutex_;
  std::string bytes_;
};

// restart_ms: a receiver that goes away stops the pipeline (counted), and once it is back the sink
// builds the pipeline again and whole frames flow to it, in order.
TEST(GstreamerSink, ARestartedPipelineReachesAReceiverThatCameBack) {
  constexpr int kWidth = 64, kHeight = 48;
  constexpr size_t kFrameBytes = size_t(kWidth) * kHeight * 3;
  auto first = std::make_unique<TcpReceiver>();
  const uint16_t port = first->port();
  GstreamerSinkConfig config = pipeline(fmt::format("appsrc name=arpipe ! tcpclientsink host=127.0.0.1 port={} sync=false", port));
  config.restart_ms = 200;
  GstreamerSink sink(config);
  std::vector<std::string> sent;
  uint64_t index = 0;
  const auto send = [&] {
    auto ctx = frame(index++, kWidth, kHeight);
    sent.push_back(packed(ctx->output));
    sink.consume_shared(ctx);
  };
  for (int i = 0; i < 5; ++i) send();
  for (int i = 0; i < 100 && first->bytes().size() < 5 * kFrameBytes; ++i) std::this_thread::sleep_for(20ms);
  ASSERT_EQ(first->bytes().size(), 5 * kFrameBytes);
  EXPECT_TRUE(first->bytes() == sent[0] + sent[1] + sent[2] + sent[3] + sent[4]);

  // The receiver goes away: writes fail within a few frames.
  first->close();
  for (int i = 0; i < 100 && sink.failures() == 0; ++i) {
    send();
    std::this_thread::sleep_for(20ms);
  }
  ASSERT_GT(sink.failures(), 0u);
  EXPECT_EQ(sink.restarts(), 0u);

  // Back on the same port: within a few restart periods the sink reaches it, and whole frames
  // arrive, each one of those sent, in order.
  TcpReceiver second(port);
  for (int i = 0; i < 150 && second.bytes().size() < 3 * kFrameBytes; ++i) {
    send();
    std::this_thread::sleep_for(20ms);
  }
  EXPECT_GE(sink.restarts(), 1u);
  std::string got = second.bytes();
  ASSERT_GE(got.size(), 3 * kFrameBytes);
  got.resize(got.size() / kFrameBytes * kFrameBytes);
  size_t next = 0;
  for (size_t at = 0; at < got.size(); at += kFrameBytes) {
    const std::string received = got.substr(at, kFrameBytes);
    size_t found = next;
    while (found < sent.size() && sent[found] != received) ++found;
    ASSERT_LT(found, sent.size()) << "received frame " << at / kFrameBytes << " is none of those sent after the last";
    next = found + 1;
  }
  sink.flush();
}

TEST(GstreamerSink, AStalledPipelineNeverHoldsTheSinkLongerThanItsTimeout) {
  GstreamerSinkConfig config = pipeline("appsrc name=arpipe ! queue max-size-buffers=1 ! identity sleep-time=1000000 ! fakesink");
  config.eos_timeout_ms = 200;
  const auto start = std::chrono::steady_clock::now();
  {
    GstreamerSink sink(config);
    double slowest = 0;
    for (uint64_t i = 0; i < 12; ++i) {
      const auto t = std::chrono::steady_clock::now();
      sink.consume_shared(frame(i, 320, 240));
      slowest = std::max(slowest, std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count());
    }
    EXPECT_LT(slowest, 1.0);
    EXPECT_GT(sink.failures(), 0u);
    sink.flush();
  }
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 8.0);
}

// Refused when the daemon starts, naming the key and saying why: an element that is not installed,
// no appsrc named "arpipe", an appsrc alone, a syntax error, another element named "arpipe".
TEST(GstreamerSink, PipelinesThatCannotWorkAreRefusedByName) {
  for (const auto& [text, why] : std::vector<std::pair<std::string, std::string>>{
           {"appsrc name=arpipe ! no_such_element_here", "no_such_element_here"},
           {"videotestsrc ! fakesink", "no appsrc named \"arpipe\""},
           {"appsrc name=arpipe", "something it feeds"},
           {"appsrc name=arpipe ! ! fakesink", "sinks.gstreamer.pipeline"},
           {"fakesrc name=arpipe ! fakesink", "no appsrc named \"arpipe\""}}) {
    try {
      GstreamerSink sink(pipeline(text));
      ADD_FAILURE() << text << ": accepted";
    } catch (const std::runtime_error& e) {
      const std::string said = e.what();
      EXPECT_EQ(said.rfind("sinks.gstreamer.pipeline = \"" + text + "\": ", 0), 0u) << said;
      EXPECT_NE(said.find(why), std::string::npos) << said;
    }
  }
}

// A file that cannot be opened shows when the run starts (outputs open only then): logged, the
// frames counted as not delivered, nothing thrown, and the sink still ends.
TEST(GstreamerSink, AnOutputThatCannotOpenIsCountedNotThrown) {
  GstreamerSink sink(pipeline("appsrc name=arpipe ! filesink location=/nonexistent-dir/x/y.mkv"));
  sink.run_started();
  for (uint64_t i = 0; i < 3; ++i) sink.consume_shared(frame(i, 64, 48));
  EXPECT_EQ(sink.frames_pushed(), 0u);
  EXPECT_EQ(sink.failures(), 3u);
  sink.flush();
}

// A sink made and dropped before the run is up (a later setup step failed) leaves the last run's file.
TEST(GstreamerSink, AFailedStartLeavesTheLastRunsFile) {
  const fs::path dir = test_dir("kept");
  const fs::path file = dir / "out.mkv";
  std::ofstream(file) << "the last run's video";
  { GstreamerSink sink(pipeline("appsrc name=arpipe ! matroskamux ! filesink location=" + file.string())); }
  EXPECT_EQ(read_bytes(file), "the last run's video");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace arpipe
