// arpiped's control socket: a Unix socket (group-read-writable, in the service's runtime
// directory) on which `arpipe ctl` sends one request line and gets one JSON reply line, followed
// by raw bytes for a snapshot. One client at a time, each with a time limit, on a thread of its own.
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include "apps/common/control_request.h"
#include "capture/sinks/http/listen_socket.h"

namespace arpipe {

struct ControlReply {
  std::string json;     // one JSON object, "ok" true or false
  std::string payload;  // bytes after the line (a snapshot's image); its size is in the JSON
};

class ControlServer {
 public:
  using Handler = std::function<ControlReply(const ControlRequest&)>;
  // Binds the socket and starts serving; throws std::runtime_error naming the path when it cannot.
  ControlServer(const std::filesystem::path& path, Handler handler);
  ~ControlServer();  // stops serving, removes the socket
  ControlServer(const ControlServer&) = delete;
  ControlServer& operator=(const ControlServer&) = delete;

  const std::string& path() const { return socket_->bound(); }

 private:
  void serve();
  void answer(int client);

  Handler handler_;
  std::unique_ptr<ListenSocket> socket_;
  int wake_fd_ = -1;
  std::thread thread_;
};

// Where the control socket goes for this config and environment: control.socket, or when it is
// "", $RUNTIME_DIRECTORY/control.sock (systemd's RuntimeDirectory=); nullopt when there is none.
std::optional<std::filesystem::path> control_socket_path(const std::string& configured);

}  // namespace arpipe
