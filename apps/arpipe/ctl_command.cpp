// arpipe ctl: talks to a running arpiped over its control socket (status, reload, set, snapshot,
// record start/stop). The daemon validates a set like --set and applies it like a reload.
#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "apps/arpipe/commands.h"
#include "apps/cli/command_line.h"
#include "apps/common/control_request.h"

namespace fs = std::filesystem;

namespace arpipe {

namespace {

// The daemon answers a reload once it is applied, which may take a bake's time: up to a minute.
constexpr int kReplyTimeoutS = 90;

struct CtlOptions {
  std::string socket;
  std::vector<std::string> assignments;
  std::string file;
  std::string dir;
};

std::string default_socket() {
  if (const char* env = std::getenv("ARPIPE_CONTROL_SOCKET"); env && *env) return env;
  return "/run/arpipe/control.sock";  // RuntimeDirectory=arpipe in systemd/arpiped.service
}

// Sends the request; returns the reply's JSON and, when it announces "bytes", that many bytes after it.
int exchange(const std::string& socket_path, const ControlRequest& request, nlohmann::json& reply, std::string& payload) {
  const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  if (socket_path.size() >= sizeof address.sun_path) {
    fmt::print(stderr, "arpipe ctl: {}: the path is too long for a Unix socket\n", socket_path);
    ::close(fd);
    return 1;
  }
  std::memcpy(address.sun_path, socket_path.c_str(), socket_path.size() + 1);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0) {
    fmt::print(stderr, "arpipe ctl: cannot connect to {}: {} (is arpiped running with a control socket? --socket or ARPIPE_CONTROL_SOCKET names another)\n",
               socket_path, std::strerror(errno));
    ::close(fd);
    return 1;
  }
  timeval tv{};
  tv.tv_sec = kReplyTimeoutS;
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  const std::string line = control_request_line(request) + "\n";
  if (::send(fd, line.data(), line.size(), MSG_NOSIGNAL) != ssize_t(line.size())) {
    fmt::print(stderr, "arpipe ctl: {}: the daemon did not take the request\n", socket_path);
    ::close(fd);
    return 1;
  }
  std::string received;
  char chunk[65536];
  size_t newline = std::string::npos;
  for (;;) {
    newline = received.find('\n');
    if (newline != std::string::npos) {
      reply = nlohmann::json::parse(received.substr(0, newline), nullptr, false);
      if (reply.is_discarded() || !reply.is_object()) break;
      const size_t want = reply.contains("bytes") && reply["bytes"].is_number_unsigned() ? reply["bytes"].get<size_t>() : 0;
      if (received.size() - newline - 1 >= want) {
        payload = received.substr(newline + 1, want);
        ::close(fd);
        return 0;
      }
    }
    const ssize_t n = ::recv(fd, chunk, sizeof chunk, 0);
    if (n <= 0) break;
    received.append(chunk, size_t(n));
  }
  ::close(fd);
  fmt::print(stderr, "arpipe ctl: {}: no complete answer from the daemon\n", socket_path);
  return 1;
}

// Prints the reply's message or error; 0 when the daemon said ok, 1 when it refused.
int report(const nlohmann::json& reply) {
  const bool ok = reply.value("ok", false);
  if (reply.contains("error")) fmt::print(stderr, "arpipe ctl: {}\n", reply["error"].get<std::string>());
  if (reply.contains("message")) fmt::print("{}\n", reply["message"].get<std::string>());
  return ok ? 0 : 1;
}

int run(const CtlOptions& options, const ControlRequest& request) {
  nlohmann::json reply;
  std::string payload;
  if (const int status = exchange(options.socket, request, reply, payload)) return status;
  if (request.kind == ControlRequest::Kind::Status && reply.value("ok", false)) {
    fmt::print("{}\n", reply["status"].dump(2));
    return 0;
  }
  if (request.kind == ControlRequest::Kind::Snapshot && reply.value("ok", false)) {
    std::ofstream out(options.file, std::ios::binary);
    out.write(payload.data(), std::streamsize(payload.size()));
    if (!out.flush()) {
      fmt::print(stderr, "arpipe ctl: cannot write {}\n", options.file);
      return 1;
    }
    fmt::print("{}: frame {} ({}x{}, {} bytes)\n", options.file, reply["sequence"].get<uint64_t>(), reply["width"].get<int>(),
               reply["height"].get<int>(), payload.size());
    return 0;
  }
  return report(reply);
}

}  // namespace

void add_ctl_command(CLI::App& arpipe) {
  CLI::App* ctl = arpipe.add_subcommand("ctl", "talk to a running arpiped over its control socket");
  auto options = std::make_shared<CtlOptions>();
  options->socket = default_socket();
  ctl->add_option("--socket", options->socket, "the daemon's control socket (default: $ARPIPE_CONTROL_SOCKET, else /run/arpipe/control.sock)")
      ->type_name("PATH")
      ->capture_default_str();
  ctl->require_subcommand(1);

  CLI::App* status = ctl->add_subcommand("status", "the pipeline's counters, timings, sinks and camera, as JSON");
  cli::on_run(status, [options] { return run(*options, ControlRequest::of(ControlRequest::Kind::Status)); });

  CLI::App* reload = ctl->add_subcommand("reload", "re-read the config file, as SIGHUP does; says what was applied or why not");
  cli::on_run(reload, [options] { return run(*options, ControlRequest::of(ControlRequest::Kind::Reload)); });

  CLI::App* set = ctl->add_subcommand("set", "change keys while running: checked like --set, applied like a reload, kept until a restart");
  set->add_option("KEY=VALUE", options->assignments, "section.key=value (a TOML value; a bare word is a string)")->required();
  cli::on_run(set, [options] {
    ControlRequest request = ControlRequest::of(ControlRequest::Kind::Set);
    request.assignments = options->assignments;
    return run(*options, request);
  });

  CLI::App* snapshot = ctl->add_subcommand("snapshot", "write the newest composited frame to FILE (.png, or .jpg)");
  snapshot->add_option("FILE", options->file, "where the picture goes")->required();
  cli::on_run(snapshot, [options] {
    ControlRequest request = ControlRequest::of(ControlRequest::Kind::Snapshot);
    const std::string ext = fs::path(options->file).extension().string();
    if (ext == ".jpg" || ext == ".jpeg") request.format = "jpg";
    else if (ext == ".png") request.format = "png";
    else cli::usage_error(fmt::format("FILE: expected a .png or .jpg name, found {}", options->file));
    return run(*options, request);
  });

  CLI::App* record = ctl->add_subcommand("record", "start or stop recording the composited frames ([sinks.recording])");
  record->require_subcommand(1);
  CLI::App* start = record->add_subcommand("start", "record into DIR (a new directory; absolute, as the daemon sees it)");
  start->add_option("DIR", options->dir, "the recording's directory")->required();
  cli::on_run(start, [options] {
    ControlRequest request = ControlRequest::of(ControlRequest::Kind::RecordStart);
    request.path = fs::absolute(options->dir).lexically_normal().string();
    return run(*options, request);
  });
  CLI::App* stop = record->add_subcommand("stop", "stop recording (the recording is complete and replayable)");
  cli::on_run(stop, [options] { return run(*options, ControlRequest::of(ControlRequest::Kind::RecordStop)); });
}

}  // namespace arpipe
