#include "apps/arpiped/control_server.h"

#include <nlohmann/json.hpp>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>

#include "core/log.h"

namespace arpipe {

namespace {

// A client has this long to send its line; a reply that the client does not take within the
// second limit is abandoned.
constexpr int kReceiveTimeoutS = 2;
constexpr int kSendTimeoutS = 10;

void set_timeout(int fd, int option, int seconds) {
  timeval tv{};
  tv.tv_sec = seconds;
  ::setsockopt(fd, SOL_SOCKET, option, &tv, sizeof tv);
}

bool send_all(int fd, const std::string& bytes) {
  size_t sent = 0;
  while (sent < bytes.size()) {
    const ssize_t n = ::send(fd, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL);
    if (n <= 0) return false;
    sent += size_t(n);
  }
  return true;
}

std::string error_json(const std::string& error) {
  return nlohmann::json{{"ok", false}, {"error", error}}.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace

std::optional<std::filesystem::path> control_socket_path(const std::string& configured) {
  if (configured == "off") return std::nullopt;
  if (!configured.empty()) return std::filesystem::path(configured);
  const char* runtime = std::getenv("RUNTIME_DIRECTORY");  // systemd: RuntimeDirectory=arpipe
  if (!runtime || !*runtime) return std::nullopt;
  // It may list several directories, separated by colons: the first is ours.
  std::string first(runtime);
  first = first.substr(0, first.find(':'));
  return std::filesystem::path(first) / "control.sock";
}

ControlServer::ControlServer(const std::filesystem::path& path, Handler handler) : handler_(std::move(handler)) {
  std::string why;
  const std::optional<ListenAddress> address = parse_listen_address(path.string(), why);
  if (!address || address->kind != ListenAddress::Kind::Unix)
    throw std::runtime_error("control.socket = \"" + path.string() + "\": expected an absolute path or one starting with \"./\"");
  socket_ = std::make_unique<ListenSocket>(*address);
  wake_fd_ = ::eventfd(0, EFD_CLOEXEC);
  if (wake_fd_ < 0) throw std::runtime_error("control socket: eventfd failed");
  thread_ = std::thread([this] { serve(); });
  log::info("control socket: {} (arpipe ctl --socket {} status)", socket_->bound(), socket_->bound());
}

ControlServer::~ControlServer() {
  const uint64_t one = 1;
  [[maybe_unused]] const ssize_t n = ::write(wake_fd_, &one, sizeof one);
  if (thread_.joinable()) thread_.join();
  ::close(wake_fd_);
}

void ControlServer::serve() {
  for (;;) {
    pollfd fds[2] = {{socket_->fd(), POLLIN, 0}, {wake_fd_, POLLIN, 0}};
    if (::poll(fds, 2, -1) < 0) {
      if (errno == EINTR) continue;
      return;
    }
    if (fds[1].revents) return;
    const int client = ::accept4(socket_->fd(), nullptr, nullptr, SOCK_CLOEXEC);
    if (client < 0) continue;
    answer(client);
    ::close(client);
  }
}

void ControlServer::answer(int client) {
  set_timeout(client, SO_RCVTIMEO, kReceiveTimeoutS);
  set_timeout(client, SO_SNDTIMEO, kSendTimeoutS);
  std::string line;
  char chunk[4096];
  // A client that trickles its line (a byte every second) would hold the socket: the whole line
  // must come within the receive limit, not each piece.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(kReceiveTimeoutS);
  while (line.find('\n') == std::string::npos) {
    if (line.size() > kMaxControlRequestBytes) {
      send_all(client, error_json("the request is longer than 64 KiB") + "\n");
      return;
    }
    if (std::chrono::steady_clock::now() > deadline) {
      send_all(client, error_json("the request line took longer than 2 s") + "\n");
      return;
    }
    const ssize_t n = ::recv(client, chunk, sizeof chunk, 0);
    if (n <= 0) {
      // A client that sends nothing in time, or half a line and goes: nothing to answer.
      if (!line.empty()) send_all(client, error_json("expected one request line ending in a newline") + "\n");
      return;
    }
    line.append(chunk, size_t(n));
  }
  line.resize(line.find('\n'));
  std::string why;
  const std::optional<ControlRequest> request = parse_control_request(line, why);
  if (!request) {
    send_all(client, error_json("expected " + why) + "\n");
    return;
  }
  ControlReply reply;
  try {
    reply = handler_(*request);
  } catch (const std::exception& e) {
    reply = {error_json(e.what()), {}};
  }
  if (send_all(client, reply.json + "\n")) send_all(client, reply.payload);
}

}  // namespace arpipe
