// arpiped speaks sd_notify: READY once set up, STATUS while running, WATCHDOG pings at half the
// interval systemd asks for, STOPPING on SIGTERM. A datagram socket of the test stands in for systemd.
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/un.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "tests/e2e/child_process.h"

namespace fs = std::filesystem;

namespace {

const fs::path kCapture = fs::path(ARPIPE_BINARY_DIR) / "default-capture";

// The receiving end of $NOTIFY_SOCKET.
class NotifySocket {
 public:
  explicit NotifySocket(const fs::path& path) : path_(path) {
    fs::remove(path_);
    fd_ = socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    std::snprintf(addr.sun_path, sizeof addr.sun_path, "%s", path_.c_str());
    bind_ok_ = bind(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0;
    timeval timeout{0, 100'000};
    setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout);
  }
  ~NotifySocket() {
    close(fd_);
    fs::remove(path_);
  }
  bool ok() const { return bind_ok_; }
  // Every message received until the deadline.
  void collect(std::vector<std::string>& out, std::chrono::milliseconds for_how_long) {
    const auto deadline = std::chrono::steady_clock::now() + for_how_long;
    char buffer[4096];
    while (std::chrono::steady_clock::now() < deadline) {
      const ssize_t n = recv(fd_, buffer, sizeof buffer, 0);
      if (n > 0) out.emplace_back(buffer, size_t(n));
    }
  }

 private:
  fs::path path_;
  int fd_ = -1;
  bool bind_ok_ = false;
};

size_t count_containing(const std::vector<std::string>& messages, const std::string& what) {
  size_t n = 0;
  for (const auto& m : messages) n += m.find(what) != std::string::npos;
  return n;
}

TEST(SystemdNotify, ReadyStatusWatchdogAndStopping) {
  const fs::path dir = fs::path(ARPIPE_BINARY_DIR) / "e2e-out" / "systemd-notify";
  fs::remove_all(dir);
  fs::create_directories(dir);
  // sun_path holds about 100 bytes, so the socket lives in /tmp.
  const fs::path socket_path = fs::temp_directory_path() / ("arpipe-notify-" + std::to_string(getpid()));
  NotifySocket notify(socket_path);
  ASSERT_TRUE(notify.ok());
  const fs::path config = dir / "arpipe.toml";
  std::ofstream(config) << "[source]\npath = \"" << kCapture.string()
                        << "\"\npacing = \"timestamps\"\nloop = true\n"
                        << "[sinks.png]\nenabled = false\n[sinks.y4m]\nenabled = false\n"
                        << "[sinks.results]\npath = \"" << (dir / "results.jsonl").string() << "\"\n";
  arpipe::test::ChildProcess child(arpipe::test::build_program("arpiped"), {"--config", config.string()}, dir / "logs",
                                   {"NOTIFY_SOCKET=" + socket_path.string(), "WATCHDOG_USEC=1000000"});
  std::vector<std::string> messages;
  // Startup (the GL context, the lens map built on the first drawn frame) takes longer in a
  // sanitizer build; the watchdog is counted from the first ping, once frames flow.
  const auto started = std::chrono::steady_clock::now();
  while (count_containing(messages, "WATCHDOG=1") == 0 &&
         std::chrono::steady_clock::now() - started < std::chrono::seconds(30))
    notify.collect(messages, std::chrono::milliseconds(100));
  const size_t before = count_containing(messages, "WATCHDOG=1");
  notify.collect(messages, std::chrono::milliseconds(3500));
  const size_t pings = count_containing(messages, "WATCHDOG=1") - before;
  child.signal(SIGTERM);
  notify.collect(messages, std::chrono::milliseconds(500));
  const int status = child.wait(std::chrono::seconds(30));
  ASSERT_TRUE(status != -1 && WIFEXITED(status)) << child.stderr_text();
  EXPECT_EQ(WEXITSTATUS(status), 0) << child.stderr_text();

  EXPECT_EQ(count_containing(messages, "READY=1"), 1u);
  EXPECT_GE(count_containing(messages, "STATUS="), 1u);
  // WatchdogSec=1 s: pings every 0.5 s while frames flow, so at least 5 in 3.5 s.
  EXPECT_GE(pings, 5u);
  EXPECT_EQ(count_containing(messages, "STOPPING=1"), 1u);
  // READY comes first: nothing is announced before the pipeline is set up.
  ASSERT_FALSE(messages.empty());
  EXPECT_NE(messages.front().find("READY=1"), std::string::npos) << messages.front();
}

}  // namespace
