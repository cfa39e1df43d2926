// arpiped's control socket through `arpipe ctl`, both real processes: status reports the running
// pipeline, set is checked like --set (a bad key refused, naming it) and applied like a reload,
// snapshot writes the newest composited frame, record start/stop leaves a replayable recording
// of the frames in between, and malformed requests are refused without harm.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <sys/stat.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include <opencv2/imgcodecs.hpp>

#include "apps/common/control_request.h"
#include "bench/http_client.h"
#include "capture/recording/recording_reader.h"
#include "tests/e2e/child_process.h"
#include "tests/e2e/e2e_test_dir.h"

namespace fs = std::filesystem;
using namespace arpipe;
using namespace std::chrono_literals;

namespace {

class ControlSocket : public test::E2eTestDir {
 protected:
  void SetUp() override {
    E2eTestDir::SetUp();
    socket_ = dir_ / "control.sock";
    const fs::path config = dir_ / "arpipe.toml";
    std::ofstream(config) << "[source]\npath = \"" << test::kDefaultCapture.string()
                          << "\"\npacing = \"timestamps\"\nloop = true\n"
                          << "[control]\nsocket = \"" << socket_.string() << "\"\n"
                          << "[[render.objects]]\nmesh = \"builtin:cube\"\n";
    daemon_ = std::make_unique<test::ChildProcess>(test::build_program("arpiped"),
                                                   std::vector<std::string>{"--config", config.string()}, dir_ / "log");
    ASSERT_TRUE(daemon_->wait_for_stderr("control socket: ", 60s)) << daemon_->stderr_text();
  }
  void TearDown() override {
    if (!daemon_) return;
    daemon_->signal(SIGTERM);
    const int status = daemon_->wait(30s);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << daemon_->stderr_text();
    EXPECT_FALSE(fs::exists(socket_));  // removed on exit
  }
  // arpipe ctl ARGS...: its exit code, stdout and stderr.
  int ctl(std::vector<std::string> args, std::string* out = nullptr, std::string* err = nullptr) {
    args.insert(args.begin(), {"ctl", "--socket", socket_.string()});
    const fs::path log = dir_ / fmt_name(args);
    test::ChildProcess child(test::build_program("arpipe"), args, log);
    const int status = child.wait(120s);
    if (out) *out = child.stdout_text();
    if (err) *err = child.stderr_text();
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }
  static std::string fmt_name(const std::vector<std::string>& args) {
    static int n = 0;
    return "ctl-" + std::to_string(n++) + "-" + args[3];
  }
  fs::path socket_;
  std::unique_ptr<test::ChildProcess> daemon_;
};

TEST_F(ControlSocket, StatusSnapshotAndSet) {
  struct stat st {};
  ASSERT_EQ(::stat(socket_.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0660u);  // the service's group, nobody else

  // Frames flow: status counts them.
  nlohmann::json status;
  for (int i = 0; i < 100; ++i) {
    std::string out;
    ASSERT_EQ(ctl({"status"}, &out), 0);
    status = nlohmann::json::parse(out);
    if (status["pipeline"]["frames_out"].get<uint64_t>() > 3) break;
    std::this_thread::sleep_for(200ms);
  }
  EXPECT_GT(status["pipeline"]["frames_out"].get<uint64_t>(), 3u);
  // Paced at the capture's 30 frames/s the pipeline keeps up, so a frame rarely waits for the one
  // before it; the count is there and at most the frames in.
  EXPECT_LE(status["pipeline"]["frames_overlapped"].get<uint64_t>(), status["pipeline"]["frames_in"].get<uint64_t>());
  EXPECT_EQ(status["camera"]["live"], false);
  EXPECT_NE(status["camera"]["source"].get<std::string>().find("default-capture"), std::string::npos);

  // The newest composited frame, as PNG: the capture's size.
  const fs::path png = dir_ / "snapshot.png";
  std::string out, err;
  ASSERT_EQ(ctl({"snapshot", png.string()}, &out, &err), 0) << err;
  const cv::Mat image = cv::imread(png.string(), cv::IMREAD_COLOR);
  ASSERT_FALSE(image.empty());
  EXPECT_EQ(image.cols, 640);
  EXPECT_EQ(image.rows, 480);

  // set: applied like a reload and said so; a key that does not exist is refused, naming it.
  ASSERT_EQ(ctl({"set", "render.blur.method=off"}, &out, &err), 0) << err;
  EXPECT_NE(out.find("reload applied: render.blur"), std::string::npos) << out;
  EXPECT_EQ(ctl({"set", "render.no_such_key=1"}, &out, &err), 1);
  EXPECT_NE(err.find("render.no_such_key"), std::string::npos) << err;
  // A key that needs a restart is refused too.
  EXPECT_EQ(ctl({"set", "pipeline.queue_depth=9"}, &out, &err), 1);
  EXPECT_NE(err.find("pipeline.queue_depth needs a restart"), std::string::npos) << err;
  // The applied set stays for a later reload (the file alone would turn the blur back on).
  ASSERT_EQ(ctl({"reload"}, &out, &err), 0) << err;
  EXPECT_NE(out.find("no key changed"), std::string::npos) << out;

  // A usage error: exit 2, nothing sent.
  EXPECT_EQ(ctl({"snapshot", (dir_ / "snapshot.gif").string()}, &out, &err), 2);
}

TEST_F(ControlSocket, RecordStartAndStopLeaveAReplayableRecording) {
  const fs::path recording = dir_ / "recorded";
  std::string out, err;
  const auto frames_out = [&] {
    std::string status;
    return ctl({"status"}, &status) == 0 ? nlohmann::json::parse(status)["pipeline"]["frames_out"].get<uint64_t>() : 0;
  };
  ASSERT_EQ(ctl({"record", "start", recording.string()}, &out, &err), 0) << err;
  EXPECT_NE(out.find("sinks.recording"), std::string::npos) << out;
  // At least 15 frames go by (half a second at 30 frames/s; longer under the sanitizers).
  const uint64_t started = frames_out();
  for (int i = 0; i < 300 && frames_out() < started + 15; ++i) std::this_thread::sleep_for(100ms);
  ASSERT_EQ(ctl({"record", "stop"}, &out, &err), 0) << err;
  const RecordingReader reader(recording);
  EXPECT_GT(reader.frame_count(), 10u);
  EXPECT_EQ(reader.info().width, 640);
  // Starting again into the same directory is refused: it holds a recording already.
  EXPECT_EQ(ctl({"record", "start", recording.string()}, &out, &err), 1);
  EXPECT_NE(err.find(recording.string()), std::string::npos) << err;
}

TEST_F(ControlSocket, MalformedRequestsAreRefusedAndTheDaemonGoesOn) {
  for (const std::string& request : {std::string("not json\n"), std::string("{\"command\": 3}\n"),
                                    std::string("{\"command\": \"set\", \"assignments\": []}\n"),
                                    std::string("{\"command\": \"record\", \"action\": \"pause\"}\n"),
                                    std::string(70'000, '{') + "\n"}) {
    HttpConnection c(socket_.string(), 5s);
    ASSERT_TRUE(c.connected());
    c.send_all(request);
    const std::string reply = c.read_body(HttpResponse{});
    const auto j = nlohmann::json::parse(reply.substr(0, reply.find('\n')), nullptr, false);
    ASSERT_FALSE(j.is_discarded()) << reply;
    EXPECT_FALSE(j["ok"].get<bool>());
    EXPECT_TRUE(j.contains("error"));
  }
  // A client that connects and says nothing is dropped after its time limit; others still get answers.
  HttpConnection silent(socket_.string(), 10s);
  std::string out;
  EXPECT_EQ(ctl({"status"}, &out), 0);
}

TEST(ControlRequest, ParsesWhatCtlSendsAndRefusesTheRest) {
  ControlRequest set = ControlRequest::of(ControlRequest::Kind::Set);
  set.assignments = {"sinks.png.dir=\"a b\"", "render.msaa_samples=1"};
  std::string why;
  const auto parsed = parse_control_request(control_request_line(set), why);
  ASSERT_TRUE(parsed) << why;
  EXPECT_EQ(parsed->kind, ControlRequest::Kind::Set);
  EXPECT_EQ(parsed->assignments, set.assignments);
  ControlRequest record = ControlRequest::of(ControlRequest::Kind::RecordStart);
  record.path = "/tmp/x";
  const auto parsed_record = parse_control_request(control_request_line(record), why);
  ASSERT_TRUE(parsed_record);
  EXPECT_EQ(parsed_record->path, "/tmp/x");
  for (const char* bad : {"", "[]", "{\"command\":\"status\"", "{\"command\":\"snapshot\",\"format\":\"gif\"}",
                          "{\"command\":\"record\",\"action\":\"start\"}", "{\"command\":\"set\",\"assignments\":[\"novalue\"]}"})
    EXPECT_FALSE(parse_control_request(bad, why)) << bad;
  EXPECT_FALSE(parse_control_request(std::string(kMaxControlRequestBytes + 1, ' '), why));
}

}  // namespace
