// The live HTTP outputs through real sockets on loopback: every path's answer checked against the
// frames published (pixels, sequence numbers), each frame encoded once for any number of stream
// clients and not at all without one, and clients that misbehave (stalled, slow-loris, malformed,
// oversized, a thousand connect/disconnect cycles) leaving the sink serving the others.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <turbojpeg.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <thread>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "capture/sinks/http/http_sink.h"
#include "core/system/frame_memory.h"
#include "core/pipeline/monotonic_clock.h"
#include "bench/http_client.h"

namespace arpipe {
namespace {

using namespace std::chrono_literals;



// A smooth picture (JPEG keeps it within a few levels) that differs per index.
std::shared_ptr<const FrameContext> smooth_frame(uint64_t index, int width = 320, int height = 240) {
  auto ctx = std::make_shared<FrameContext>();
  ctx->input_index = index;
  ctx->camera.meta.sequence = 500 + index;
  ctx->camera.meta.exposure_start_ns = 7'000'000'000 + int64_t(index) * 33'000'000;
  ctx->output = Frame::allocate(PixelFormat::RGB24, width, height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      uint8_t* p = &ctx->output.data[size_t(y) * ctx->output.bytes_per_line + size_t(x) * 3];
      p[0] = uint8_t((x + index * 7) % 256);
      p[1] = uint8_t(y % 256);
      p[2] = uint8_t(128 + 100 * std::sin((x + y) * 0.02 + double(index)));
    }
  ctx->arrived_ns = monotonic_now_ns();
  return ctx;
}

struct Served {
  explicit Served(HttpSinkConfig config = {}, bool connected = true) : camera_connected(connected) {
    config.enabled = true;
    if (config.listen == HttpSinkConfig{}.listen) config.listen = "127.0.0.1:0";
    sink = std::make_unique<HttpSink>(config, [this] {
      PipelineStatus status;
      status.source = "test source";
      status.source_connected = camera_connected;
      status.sinks.push_back({"sinks.http", 3, 1, 0});
      status.metrics.frames_in = 3;
      status.metrics.frames_overlapped = 2;
      status.metrics.stages["render"].runs = 3;
      status.metrics.stages["render"].seconds.add(0.004);
      status.metrics.stages["render"].skips["reused: pose, light and objects unchanged"] = 1;
      return status;
    });
    address = sink->bound();
  }
  std::atomic<bool> camera_connected;
  std::unique_ptr<HttpSink> sink;
  std::string address;
};

// Decoded RGB pixels of a JPEG, and its size.
std::vector<uint8_t> decode_jpeg(const std::string& jpeg, int& width, int& height) {
  tjhandle handle = tjInitDecompress();
  int subsampling = 0, colorspace = 0;
  std::vector<uint8_t> rgb;
  if (tjDecompressHeader3(handle, reinterpret_cast<const unsigned char*>(jpeg.data()), jpeg.size(), &width, &height,
                          &subsampling, &colorspace) == 0) {
    rgb.resize(size_t(width) * size_t(height) * 3);
    if (tjDecompress2(handle, reinterpret_cast<const unsigned char*>(jpeg.data()), jpeg.size(), rgb.data(), width, 0,
                      height, TJPF_RGB, 0) != 0)
      rgb.clear();
  }
  tjDestroy(handle);
  return rgb;
}

double mean_abs_difference(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b) {
  if (a.size() != b.size() || a.empty()) return 1e9;
  double sum = 0;
  for (size_t i = 0; i < a.size(); ++i) sum += std::abs(int(a[i]) - int(b[i]));
  return sum / double(a.size());
}

TEST(HttpSink, PageStateAndMetricsAnswerBeforeTheFirstFrame) {
  Served s;
  auto page = http_request(s.address, "/");
  ASSERT_TRUE(page);
  EXPECT_EQ(page->status, 200);
  EXPECT_EQ(page->headers["content-type"], "text/html; charset=utf-8");
  EXPECT_NE(page->body.find("<img id=\"stream\" src=\"stream.mjpg\""), std::string::npos);
  // Self-contained: nothing fetched from elsewhere.
  EXPECT_EQ(page->body.find("http://"), std::string::npos);
  EXPECT_EQ(page->body.find("https://"), std::string::npos);

  auto state = http_request(s.address, "/state");
  ASSERT_TRUE(state);
  EXPECT_EQ(state->status, 200);
  const auto j = nlohmann::json::parse(state->body);
  EXPECT_TRUE(j["frame"].is_null());
  EXPECT_EQ(j["camera"]["source"], "test source");

  auto snapshot = http_request(s.address, "/snapshot.jpg");
  ASSERT_TRUE(snapshot);
  EXPECT_EQ(snapshot->status, 503);

  auto missing = http_request(s.address, "/../../etc/passwd");
  ASSERT_TRUE(missing);
  EXPECT_EQ(missing->status, 404);
  auto post = http_request(s.address, "/state", "POST");
  ASSERT_TRUE(post);
  EXPECT_EQ(post->status, 405);
}

TEST(HttpSink, SnapshotsAreTheLatestFrame) {
  Served s;
  for (uint64_t i = 0; i < 3; ++i) s.sink->consume_shared(smooth_frame(i));
  const auto latest = smooth_frame(2);

  auto png = http_request(s.address, "/snapshot.png");
  ASSERT_TRUE(png);
  EXPECT_EQ(png->status, 200);
  EXPECT_EQ(png->headers["content-type"], "image/png");
  EXPECT_EQ(png->headers["x-arpipe-sequence"], "502");
  cv::Mat decoded = cv::imdecode(std::vector<uint8_t>(png->body.begin(), png->body.end()), cv::IMREAD_COLOR), rgb;
  ASSERT_FALSE(decoded.empty());
  cv::cvtColor(decoded, rgb, cv::COLOR_BGR2RGB);
  ASSERT_EQ(rgb.cols, 320);
  ASSERT_EQ(rgb.rows, 240);
  // PNG is lossless: byte for byte the composited frame.
  EXPECT_EQ(std::vector<uint8_t>(rgb.data, rgb.data + rgb.total() * 3), latest->output.data);

  auto jpg = http_request(s.address, "/snapshot.jpg");
  ASSERT_TRUE(jpg);
  EXPECT_EQ(jpg->status, 200);
  EXPECT_EQ(jpg->headers["content-type"], "image/jpeg");
  int width = 0, height = 0;
  const std::vector<uint8_t> pixels = decode_jpeg(jpg->body, width, height);
  EXPECT_EQ(width, 320);
  EXPECT_EQ(height, 240);
  // JPEG at quality 85 on a smooth picture: within 3 levels on average (measured about 1).
  EXPECT_LT(mean_abs_difference(pixels, latest->output.data), 3.0);
}

TEST(HttpSink, EachFrameIsEncodedOnceForEightClientsAndNotAtAllForNone) {
  Served s;
  for (uint64_t i = 0; i < 10; ++i) s.sink->consume_shared(smooth_frame(i));
  EXPECT_EQ(s.sink->counters().jpeg_encodes, 0u);
  EXPECT_EQ(s.sink->counters().frames_not_encoded, 10u);

  std::vector<std::unique_ptr<HttpConnection>> clients;
  for (int c = 0; c < 8; ++c) {
    clients.push_back(std::make_unique<HttpConnection>(s.address));
    ASSERT_TRUE(clients.back()->send_all("GET /stream.mjpg HTTP/1.1\r\nHost: t\r\n\r\n"));
    auto head = clients.back()->read_head();
    ASSERT_TRUE(head);
    EXPECT_EQ(head->status, 200);
    EXPECT_EQ(head->headers["content-type"], "multipart/x-mixed-replace; boundary=arpipeframe");
  }
  // Wait until all eight count as watchers, then publish.
  for (int i = 0; i < 200 && s.sink->counters().stream_clients < 8; ++i) std::this_thread::sleep_for(10ms);
  ASSERT_EQ(s.sink->counters().stream_clients, 8);
  constexpr uint64_t kFrames = 20;
  std::vector<std::thread> readers;
  std::vector<std::vector<uint64_t>> sequences(clients.size());
  for (size_t c = 0; c < clients.size(); ++c)
    readers.emplace_back([&, c] {
      while (sequences[c].empty() || sequences[c].back() < 500 + 10 + kFrames - 1) {
        auto part = clients[c]->read_part();
        if (!part) return;
        if (part->headers.count("x-arpipe-sequence")) sequences[c].push_back(std::stoull(part->headers["x-arpipe-sequence"]));
      }
    });
  for (uint64_t i = 10; i < 10 + kFrames; ++i) {
    s.sink->consume_shared(smooth_frame(i));
    std::this_thread::sleep_for(5ms);
  }
  for (auto& r : readers) r.join();
  for (const auto& seen : sequences) {
    ASSERT_FALSE(seen.empty());
    EXPECT_EQ(seen.back(), 500 + 10 + kFrames - 1);  // every client reaches the last frame
    for (size_t k = 1; k < seen.size(); ++k) EXPECT_GT(seen[k], seen[k - 1]);  // in order, none twice
  }
  // Once per frame published while watched, whatever the number of clients.
  EXPECT_EQ(s.sink->counters().jpeg_encodes, kFrames);
  EXPECT_GE(s.sink->counters().stream_latency_seconds.count(), 8u);
}

TEST(HttpSink, AStalledClientDelaysNeitherTheSinkNorAnotherClient) {
  HttpSinkConfig config;
  config.client_timeout_ms = 2000;
  Served s(config);
  // The stalled client: asks for the stream with a tiny receive buffer and never reads.
  HttpConnection stalled(s.address, 10s, 4096);
  ASSERT_TRUE(stalled.send_all("GET /stream.mjpg HTTP/1.1\r\nHost: t\r\n\r\n"));
  HttpConnection reader(s.address);
  ASSERT_TRUE(reader.send_all("GET /stream.mjpg HTTP/1.1\r\nHost: t\r\n\r\n"));
  ASSERT_TRUE(reader.read_head());
  for (int i = 0; i < 200 && s.sink->counters().stream_clients < 2; ++i) std::this_thread::sleep_for(10ms);
  ASSERT_EQ(s.sink->counters().stream_clients, 2);

  // Big frames (noise hardly compresses) fill the stalled client's socket at once.
  double slowest_consume_s = 0;
  uint64_t last_seen = 0;
  for (uint64_t i = 0; i < 60; ++i) {
    auto ctx = std::make_shared<FrameContext>(*smooth_frame(i, 640, 480));
    for (size_t k = 0; k < ctx->output.data.size(); ++k) ctx->output.data[k] = uint8_t((k * 2654435761u + i) >> 13);
    const auto start = std::chrono::steady_clock::now();
    s.sink->consume_shared(ctx);
    slowest_consume_s = std::max(slowest_consume_s, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    auto part = reader.read_part();
    ASSERT_TRUE(part) << "frame " << i;
    last_seen = std::stoull(part->headers["x-arpipe-sequence"]);
  }
  EXPECT_EQ(last_seen, 500u + 59);
  // The sink's work per frame is the encoding (a few ms at 640x480), never a client's send.
  EXPECT_LT(slowest_consume_s, 0.5);
  // The stalled client is dropped after client_timeout_ms without progress, while the reader goes
  // on taking frames.
  std::atomic<bool> done{false};
  std::atomic<uint64_t> reader_last{0};
  std::thread keep_reading([&] {
    while (!done) {
      auto part = reader.read_part();
      if (!part) return;
      if (part->headers.count("x-arpipe-sequence")) reader_last = std::stoull(part->headers["x-arpipe-sequence"]);
    }
  });
  uint64_t index = 60;
  for (int i = 0; i < 100 && s.sink->counters().stream_clients > 1; ++i, ++index) {
    s.sink->consume_shared(smooth_frame(index));
    std::this_thread::sleep_for(100ms);
  }
  EXPECT_EQ(s.sink->counters().stream_clients, 1);
  EXPECT_TRUE(stalled.closed_by_server());
  s.sink->consume_shared(smooth_frame(index));
  for (int i = 0; i < 100 && reader_last != 500 + index; ++i) std::this_thread::sleep_for(20ms);
  EXPECT_EQ(reader_last, 500 + index);
  done = true;
  s.sink->consume_shared(smooth_frame(index + 1));  // wakes the reader's last read
  keep_reading.join();
}

TEST(HttpSink, MalformedOversizedSlowAndRepeatedClientsLeaveItServing) {
  HttpSinkConfig config;
  config.client_timeout_ms = 1000;
  // Room for the connections whose threads are still ending: at the limit the server stops
  // accepting, and a connect then waits for TCP's 1 s retry (the limit itself holds, only slower).
  config.max_clients = 128;
  Served s(config);
  s.sink->consume_shared(smooth_frame(0));
  // Garbage instead of a request line.
  {
    HttpConnection c(s.address, 5s);
    ASSERT_TRUE(c.send_all(std::string("\x16\x03\x01\x02\x00garbage\r\n\r\n", 16)));
    EXPECT_TRUE(c.closed_by_server() || c.read_head());
  }
  // 200 KB of headers: refused (431, or closed), never buffered whole.
  {
    HttpConnection c(s.address, 5s);
    c.send_all("GET /state HTTP/1.1\r\nHost: t\r\nX-Big: " + std::string(200'000, 'a') + "\r\n\r\n");
    std::optional<HttpResponse> head = c.read_head();
    if (head) {
      EXPECT_EQ(head->status, 431);
    }
  }
  // Slow-loris: a header byte every 300 ms, dropped after the 1 s idle limit... or rather never
  // finishing: the server must close it within a few timeouts while answering others meanwhile.
  {
    HttpConnection loris(s.address, 10s);
    ASSERT_TRUE(loris.send_all("GET /state HTTP/1.1\r\n"));
    std::thread other([&] {
      auto r = http_request(s.address, "/state");
      ASSERT_TRUE(r);
      EXPECT_EQ(r->status, 200);
    });
    other.join();
    const auto start = std::chrono::steady_clock::now();
    EXPECT_TRUE(loris.closed_by_server());  // no more bytes sent: idle for 1 s, then closed
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 5.0);
  }
  // A thousand connect/disconnect cycles, some after half a request: memory stays flat.

  for (int i = 0; i < 100; ++i) HttpConnection warmup(s.address);
  const long before = resident_memory_kib();
  for (int i = 0; i < 1000; ++i) {
    HttpConnection c(s.address, 2s);
    ASSERT_TRUE(c.connected()) << "cycle " << i;
    if (i % 2) c.send_all("GET /sta");
  }
  // Give the connection threads a moment to end.
  for (int i = 0; i < 50 && s.sink->counters().stream_clients > 0; ++i) std::this_thread::sleep_for(10ms);
  std::this_thread::sleep_for(200ms);
  const long after = resident_memory_kib();
#ifndef __SANITIZE_ADDRESS__
  EXPECT_LT(after - before, 8 * 1024) << "RSS grew from " << before << " KiB to " << after << " KiB";
#else
  // Under AddressSanitizer freed memory waits in its quarantine (up to 256 MB), so RSS measures
  // the sanitizer, not the server: the cycles run here for what ASan finds, the bound holds in
  // the plain build.
  (void)before;
  (void)after;
#endif
  auto r = http_request(s.address, "/state");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200);
}

TEST(HttpSink, APlaceholderSaysTheCameraIsAway) {
  HttpSinkConfig config;
  config.camera_away_ms = 300;
  Served s(config, /*connected=*/false);
  s.sink->consume_shared(smooth_frame(0));
  HttpConnection c(s.address);
  ASSERT_TRUE(c.send_all("GET /stream.mjpg HTTP/1.1\r\nHost: t\r\n\r\n"));
  ASSERT_TRUE(c.read_head());
  auto part = c.read_part();
  ASSERT_TRUE(part);
  EXPECT_EQ(part->headers["x-arpipe-placeholder"], "camera away");
  int width = 0, height = 0;
  EXPECT_FALSE(decode_jpeg(part->body, width, height).empty());
  EXPECT_EQ(width, 320);  // the size of the last frame
  EXPECT_EQ(height, 240);
  auto state = http_request(s.address, "/state");
  ASSERT_TRUE(state);
  EXPECT_TRUE(nlohmann::json::parse(state->body)["camera"]["away"].get<bool>());
  // Back: the stream shows camera frames again.
  s.camera_connected = true;
  s.sink->consume_shared(smooth_frame(1));
  for (int i = 0; i < 10; ++i) {
    part = c.read_part();
    ASSERT_TRUE(part);
    if (part->headers.count("x-arpipe-sequence")) break;
  }
  EXPECT_EQ(part->headers["x-arpipe-sequence"], "501");
}

TEST(HttpSink, ServesOnAUnixSocket) {
  const std::filesystem::path path = std::filesystem::temp_directory_path() / ("arpipe-http-" + std::to_string(::getpid()) + ".sock");
  HttpSinkConfig config;
  config.listen = path.string();
  {
    Served s(config);
    EXPECT_EQ(s.address, path.string());
    EXPECT_EQ(std::filesystem::status(path).type(), std::filesystem::file_type::socket);
    auto r = http_request(path.string(), "/state");
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 200);
  }
  EXPECT_FALSE(std::filesystem::exists(path));  // removed when the sink goes
}

// A reload that changes [sinks.http] makes the new sink while the old one still serves (then
// closes the old): the new one takes over the same socket, so the bind is not refused and the
// address answers throughout.
TEST(HttpSink, ANewSinkOnTheSameAddressTakesTheSocketOver) {
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("arpipe-http-reload-" + std::to_string(::getpid()) + ".sock");
  HttpSinkConfig config;
  config.listen = path.string();
  auto old_sink = std::make_unique<Served>(config);
  old_sink->sink->consume_shared(smooth_frame(0));
  config.jpeg_quality = 50;  // a change of the section: a new sink
  Served new_sink(config);
  new_sink.sink->consume_shared(smooth_frame(1));
  old_sink.reset();
  EXPECT_EQ(std::filesystem::status(path).type(), std::filesystem::file_type::socket);
  auto snapshot = http_request(path.string(), "/snapshot.png");
  ASSERT_TRUE(snapshot);
  EXPECT_EQ(snapshot->status, 200);
  EXPECT_EQ(snapshot->headers["x-arpipe-sequence"], "501");  // the new sink's frame
}

// The value of the sample whose line starts with `name_and_labels` (then a space); NaN when absent.
double sample_value(const std::string& metrics, const std::string& name_and_labels) {
  const std::string start = name_and_labels + " ";
  for (size_t at = 0; at < metrics.size();) {
    const size_t end = metrics.find('\n', at);
    const std::string line = metrics.substr(at, end == std::string::npos ? std::string::npos : end - at);
    if (line.starts_with(start)) return std::stod(line.substr(start.size()));
    if (end == std::string::npos) break;
    at = end + 1;
  }
  return std::nan("");
}

// /metrics counts the process's CPU, whole and by part of the pipeline: 50 ms this (unnamed, so
// "other") thread spends between two scrapes shows in both, and the parts never add to more
// than the whole.
TEST(HttpSink, TheMetricsCountTheProcessCpuByPart) {
  Served s;
  const auto scrape = [&] {
    auto metrics = http_request(s.address, "/metrics");
    EXPECT_TRUE(metrics);
    return metrics ? metrics->body : std::string();
  };
  const std::string before = scrape();
  timespec start{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &start);
  for (volatile double sink = 0;;) {
    sink = sink + 1.0;
    timespec now{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
    if (double(now.tv_sec - start.tv_sec) + double(now.tv_nsec - start.tv_nsec) * 1e-9 >= 0.05) break;
  }
  const std::string after = scrape();
  const double other = sample_value(after, "arpipe_cpu_seconds_total{part=\"other\"}") -
                       sample_value(before, "arpipe_cpu_seconds_total{part=\"other\"}");
  const double whole = sample_value(after, "process_cpu_seconds_total") - sample_value(before, "process_cpu_seconds_total");
  EXPECT_GE(other, 0.05 - 1e-3);
  EXPECT_GE(whole, 0.05 - 0.011);  // getrusage counts in the kernel's ticks on some kernels
  double parts = 0;
  for (const char* part : {"processing", "helper", "gl", "capture", "sinks", "other"}) {
    const double v = sample_value(after, std::string("arpipe_cpu_seconds_total{part=\"") + part + "\"}");
    if (!std::isnan(v)) parts += v;
  }
  EXPECT_LE(parts, sample_value(after, "process_cpu_seconds_total") + 0.011);
}

// promtool (Debian's prometheus package) is the reference for the text format; skipped without it.
TEST(HttpSink, PromtoolAcceptsTheMetrics) {
  Served s;
  s.sink->consume_shared(smooth_frame(0));
  auto metrics = http_request(s.address, "/metrics");
  ASSERT_TRUE(metrics);
  EXPECT_EQ(metrics->headers["content-type"], "text/plain; version=0.0.4; charset=utf-8");
  EXPECT_NE(metrics->body.find("arpipe_stage_duration_seconds_bucket{stage=\"render\",le=\"0.005\"} 1\n"), std::string::npos);
  EXPECT_NE(metrics->body.find("arpipe_stage_duration_seconds_bucket{stage=\"render\",le=\"+Inf\"} 1\n"), std::string::npos);
  EXPECT_NE(metrics->body.find("arpipe_sink_dropped_frames_total{sink=\"sinks.http\"} 1\n"), std::string::npos);
  EXPECT_NE(metrics->body.find("arpipe_http_frames_not_encoded_total 1\n"), std::string::npos);
  EXPECT_NE(metrics->body.find("arpipe_frames_overlapped_total 2\n"), std::string::npos);
  if (std::system("command -v promtool >/dev/null 2>&1") != 0) GTEST_SKIP() << "promtool is not installed";
  const std::filesystem::path file = std::filesystem::temp_directory_path() / ("arpipe-metrics-" + std::to_string(::getpid()));
  std::ofstream(file) << metrics->body;
  const std::string command = "promtool check metrics < " + file.string() + " > " + file.string() + ".out 2>&1";
  const int rc = std::system(command.c_str());
  std::ifstream out(file.string() + ".out");
  const std::string said((std::istreambuf_iterator<char>(out)), std::istreambuf_iterator<char>());
  EXPECT_EQ(rc, 0) << said;
  std::filesystem::remove(file);
  std::filesystem::remove(file.string() + ".out");
}

}  // namespace
}  // namespace arpipe
