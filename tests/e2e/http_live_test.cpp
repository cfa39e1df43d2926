// The live outputs of a real arpiped replaying the default capture in real time: /state follows
// the frames, /stream.mjpg delivers the composited frames in order, /metrics counts them, and the
// preview page, loaded in headless Chromium (Debian's chromium-headless-shell), shows a live frame
// and the frame's state, both changing.
#include <gtest/gtest.h>

#include <functional>
#include <nlohmann/json.hpp>
#include <turbojpeg.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include <opencv2/imgcodecs.hpp>

#include "bench/http_client.h"
#include "tests/e2e/child_process.h"
#include "tests/e2e/e2e_test_dir.h"

namespace fs = std::filesystem;
using namespace arpipe;
using namespace std::chrono_literals;

namespace {

class HttpLive : public test::E2eTestDir {
 protected:
  // Starts arpiped replaying the default capture in real time, looping, with the HTTP sink on a
  // port the kernel chooses; returns the address it logged.
  std::string start_daemon() {
    const fs::path config = dir_ / "arpipe.toml";
    std::ofstream(config) << "[source]\npath = \"" << test::kDefaultCapture.string()
                          << "\"\npacing = \"timestamps\"\nloop = true\n"
                          << "[sinks.http]\nlisten = \"127.0.0.1:0\"\n"
                          << "[[render.objects]]\nmesh = \"builtin:cube\"\n";
    daemon_ = std::make_unique<test::ChildProcess>(test::build_program("arpiped"),
                                                   std::vector<std::string>{"--config", config.string()}, dir_ / "log");
    const std::string said = "serving the preview on ";
    EXPECT_TRUE(daemon_->wait_for_stderr(said, 60s)) << daemon_->stderr_text();
    const std::string text = daemon_->stderr_text();
    const size_t at = text.find(said);
    if (at == std::string::npos) return {};
    const size_t start = at + said.size();
    return text.substr(start, text.find(' ', start) - start);  // "127.0.0.1:PORT"
  }
  void stop_daemon() {
    daemon_->signal(SIGTERM);
    const int status = daemon_->wait(30s);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << daemon_->stderr_text();
  }
  // The newest frame's sequence number from /state, once frames flow.
  static nlohmann::json state(const std::string& address) {
    auto r = http_request(address, "/state");
    if (!r || r->status != 200) return nullptr;
    return nlohmann::json::parse(r->body);
  }
  std::unique_ptr<test::ChildProcess> daemon_;
};

TEST_F(HttpLive, StateStreamAndMetricsFollowTheReplay) {
  const std::string address = start_daemon();
  ASSERT_FALSE(address.empty());
  // Frames flow: /state's frame advances.
  nlohmann::json first;
  for (int i = 0; i < 300 && (first.is_null() || first["frame"].is_null()); ++i) {
    first = state(address);
    std::this_thread::sleep_for(100ms);
  }
  ASSERT_FALSE(first["frame"].is_null()) << daemon_->stderr_text();
  nlohmann::json later = state(address);
  for (int i = 0; i < 100 && later["pipeline"]["frames_out"] == first["pipeline"]["frames_out"]; ++i) {
    std::this_thread::sleep_for(100ms);
    later = state(address);
  }
  EXPECT_GT(later["pipeline"]["frames_out"].get<uint64_t>(), first["pipeline"]["frames_out"].get<uint64_t>());
  EXPECT_TRUE(later["frame"].contains("track_state"));
  EXPECT_FALSE(later["camera"]["away"].get<bool>());

  // The stream: composited frames at the capture's size, in order.
  HttpConnection stream(address);
  ASSERT_TRUE(stream.send_all("GET /stream.mjpg HTTP/1.1\r\nHost: t\r\n\r\n"));
  ASSERT_TRUE(stream.read_head());
  int64_t previous_exposure = 0;
  for (int k = 0; k < 5; ++k) {
    auto part = stream.read_part();
    ASSERT_TRUE(part);
    ASSERT_TRUE(part->headers.count("x-arpipe-sequence"));
    const cv::Mat image = cv::imdecode(std::vector<uint8_t>(part->body.begin(), part->body.end()), cv::IMREAD_COLOR);
    ASSERT_FALSE(image.empty());
    EXPECT_EQ(image.cols, 640);
    EXPECT_EQ(image.rows, 480);
    const int64_t exposure = std::stoll(part->headers["x-arpipe-exposure-start-ns"]);
    // Exposures follow each other (a loop restarts the recording's times one loop period later).
    EXPECT_GT(exposure, previous_exposure);
    previous_exposure = exposure;
    EXPECT_GE(std::stod(part->headers["x-arpipe-latency-ms"]), 0.0);
  }
  auto metrics = http_request(address, "/metrics");
  ASSERT_TRUE(metrics);
  EXPECT_NE(metrics->body.find("arpipe_http_jpeg_encodes_total "), std::string::npos);
  EXPECT_NE(metrics->body.find("arpipe_sink_frames_total{sink=\"sinks.http\"}"), std::string::npos);
  EXPECT_NE(metrics->body.find("arpipe_stage_duration_seconds_bucket{stage=\"render\",le=\"+Inf\"}"), std::string::npos);
  stop_daemon();
}

// Debian's headless Chromium, installed for the tests (scripts/install-deps.sh).
std::string chromium() {
  for (const char* name : {"/usr/bin/chromium-headless-shell", "/usr/bin/chromium"})
    if (fs::exists(name)) return name;
  return {};
}

// Runs headless Chromium on the page and returns its screenshot. The page never finishes loading
// (its stream goes on): the virtual time budget lets its script poll /state before the shot (or
// the DOM dump), and the timeout ends it in any case.
cv::Mat screenshot(const std::string& browser, const std::string& url, const fs::path& png) {
  const std::string command = browser + " --no-sandbox --disable-gpu --hide-scrollbars --window-size=1100,600 --timeout=5000 --virtual-time-budget=2000 --screenshot=" +
                              png.string() + " " + url + " > " + png.string() + ".log 2>&1";
  EXPECT_EQ(std::system(command.c_str()), 0) << test::read_text(png.string() + ".log");
  return cv::imread(png.string(), cv::IMREAD_COLOR);
}

std::string dom(const std::string& browser, const std::string& url, const fs::path& out) {
  const std::string command = browser + " --no-sandbox --disable-gpu --timeout=5000 --virtual-time-budget=2000 --dump-dom " + url + " > " +
                              out.string() + " 2> " + out.string() + ".log";
  EXPECT_EQ(std::system(command.c_str()), 0) << test::read_text(out.string() + ".log");
  return test::read_text(out);
}

TEST_F(HttpLive, TheBrowserShowsALiveFrameAndItsState) {
  const std::string browser = chromium();
  if (browser.empty()) GTEST_SKIP() << "no headless Chromium (chromium-headless-shell) installed";
  const std::string address = start_daemon();
  ASSERT_FALSE(address.empty());
  for (int i = 0; i < 300 && state(address)["frame"].is_null(); ++i) std::this_thread::sleep_for(100ms);
  const std::string url = "http://" + address + "/";

  // The stream's image fills the left of the page below the header: camera content there (not the
  // page's flat background), different in the two shots (the camera moves). On a loaded machine the
  // browser may shoot before the stream's first image has arrived, as a person might see a blank
  // box before it loads: a few tries, each a fresh browser on the live page.
  constexpr int kTries = 6;
  const cv::Rect view(20, 60, 560, 400);
  const auto spread_of = [&](const cv::Mat& shot) {
    cv::Scalar mean, spread;
    cv::meanStdDev(shot(view), mean, spread);
    return spread[0] + spread[1] + spread[2];
  };
  const auto difference_of = [&](const cv::Mat& x, const cv::Mat& y) {
    cv::Mat difference;
    cv::absdiff(x(view), y(view), difference);
    return cv::mean(difference)[0] + cv::mean(difference)[1] + cv::mean(difference)[2];
  };
  // accept: whether a shot is the one wanted; else another, up to kTries.
  const auto shot_until = [&](const std::string& name, const std::function<bool(const cv::Mat&)>& accept) {
    cv::Mat shot;
    for (int i = 0; i < kTries; ++i) {
      shot = screenshot(browser, url, dir_ / name);
      if (shot.empty() || shot.cols < view.br().x || shot.rows < view.br().y) return cv::Mat();
      if (accept(shot)) break;
      std::this_thread::sleep_for(700ms);
    }
    return shot;
  };
  const cv::Mat a = shot_until("a.png", [&](const cv::Mat& shot) { return spread_of(shot) > 20.0; });
  ASSERT_FALSE(a.empty());
  // The replay loops every 2 s (60 frames at 30 frames/s) and one shot takes about as long, so a
  // second shot can rightly show the very same picture a whole loop later: then another, a
  // fraction of a loop later.
  const cv::Mat b = shot_until("b.png", [&](const cv::Mat& shot) {
    return spread_of(shot) > 20.0 && shot.size() == a.size() && difference_of(a, shot) > 1.0;
  });
  ASSERT_FALSE(b.empty());
  ASSERT_EQ(a.size(), b.size());
  EXPECT_GT(spread_of(a), 20.0) << "the stream area looks empty in " << (dir_ / "a.png");
  EXPECT_GT(spread_of(b), 20.0) << "the stream area looks empty in " << (dir_ / "b.png");
  EXPECT_GT(difference_of(a, b), 1.0) << "the frame did not change between " << (dir_ / "a.png") << " and "
                                      << (dir_ / "b.png");

  // The state panel, as the page's script filled it in: "<td id="sequence">S (index I)</td>".
  const auto frame_index = [](const std::string& html) -> long long {
    const std::string open = "<td id=\"sequence\">";
    const size_t cell = html.find(open);
    if (cell == std::string::npos) return -1;
    const std::string text = html.substr(cell + open.size(), html.find("</td>", cell) - cell - open.size());
    const size_t index = text.find("(index ");
    return index == std::string::npos ? -1 : std::atoll(text.c_str() + index + 7);
  };
  const auto dom_with_frame = [&](const std::string& name) {
    std::string html;
    for (int i = 0; i < kTries && frame_index(html) < 0; ++i) html = dom(browser, url, dir_ / name);
    return html;
  };
  const std::string dom_a = dom_with_frame("a.html");
  ASSERT_GE(frame_index(dom_a), 0) << dom_a;
  // The tracker's state, named and coloured (the capture's last frames look away from the tag, so
  // any of the three may be showing).
  const bool state_shown = dom_a.find("<td id=\"track_state\" class=\"tracking\">tracking</td>") != std::string::npos ||
                           dom_a.find("<td id=\"track_state\" class=\"predicted\">predicted</td>") != std::string::npos ||
                           dom_a.find("<td id=\"track_state\" class=\"lost\">lost</td>") != std::string::npos;
  EXPECT_TRUE(state_shown) << dom_a;
  const std::string dom_b = dom_with_frame("b.html");
  ASSERT_GE(frame_index(dom_b), 0) << dom_b;
  EXPECT_GT(frame_index(dom_b), frame_index(dom_a));
  stop_daemon();
}

}  // namespace
