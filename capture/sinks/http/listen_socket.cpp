#include "capture/sinks/http/listen_socket.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <systemd/sd-daemon.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <map>
#include <mutex>
#include <stdexcept>

#include <fmt/format.h>

namespace arpipe {

namespace {

// Connections the kernel holds for the server to accept: a burst beyond it waits for TCP's 1 s
// retry (accepting takes a thread start each).
constexpr int kBacklog = 512;

[[noreturn]] void fail(const ListenAddress& address, std::string_view what, int error) {
  throw std::runtime_error(fmt::format("listen = \"{}\": {}: {}", address.text(), what, std::strerror(error)));
}

}  // namespace

ListenSocket::ListenSocket(const ListenAddress& address) {
  if (address.kind == ListenAddress::Kind::Systemd) {
    const int count = sd_listen_fds(0);
    if (count != 1 || sd_is_socket(SD_LISTEN_FDS_START, AF_UNSPEC, SOCK_STREAM, 1) <= 0)
      throw std::runtime_error(fmt::format(
          "listen = \"systemd\": expected one listening stream socket from systemd (socket activation), got {}",
          count < 0 ? 0 : count));
    fd_ = SD_LISTEN_FDS_START;
    owned_ = false;
    bound_ = "the socket systemd passed";
    return;
  }
  if (address.kind == ListenAddress::Kind::Unix) {
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    std::memcpy(addr.sun_path, address.path.c_str(), address.path.size() + 1);  // the parser checked the length
    // A socket file left by an earlier run (a crash) is replaced; any other file is not ours.
    struct stat st {};
    if (::lstat(address.path.c_str(), &st) == 0) {
      if (!S_ISSOCK(st.st_mode)) fail(address, "the path exists and is not a socket", EEXIST);
      ::unlink(address.path.c_str());
    }
    fd_ = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (fd_ < 0) fail(address, "socket", errno);
    if (::bind(fd_, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {
      const int error = errno;
      ::close(fd_);
      fail(address, "bind", error);
    }
    unix_path_ = address.path;
    ::chmod(address.path.c_str(), 0660);
    bound_ = address.path;
  } else {
    const bool v6 = address.host.find(':') != std::string::npos;
    fd_ = ::socket(v6 ? AF_INET6 : AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (fd_ < 0) fail(address, "socket", errno);
    const int one = 1;
    ::setsockopt(fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    sockaddr_storage storage{};
    socklen_t length = 0;
    if (v6) {
      auto* a = reinterpret_cast<sockaddr_in6*>(&storage);
      a->sin6_family = AF_INET6;
      a->sin6_port = htons(address.port);
      ::inet_pton(AF_INET6, address.host.c_str(), &a->sin6_addr);
      length = sizeof *a;
    } else {
      auto* a = reinterpret_cast<sockaddr_in*>(&storage);
      a->sin_family = AF_INET;
      a->sin_port = htons(address.port);
      ::inet_pton(AF_INET, address.host.c_str(), &a->sin_addr);
      length = sizeof *a;
    }
    if (::bind(fd_, reinterpret_cast<const sockaddr*>(&storage), length) != 0) {
      const int error = errno;
      ::close(fd_);
      fail(address, "bind", error);
    }
    length = sizeof storage;
    ::getsockname(fd_, reinterpret_cast<sockaddr*>(&storage), &length);
    const uint16_t port = ntohs(v6 ? reinterpret_cast<sockaddr_in6*>(&storage)->sin6_port
                                   : reinterpret_cast<sockaddr_in*>(&storage)->sin_port);
    ListenAddress actual = address;
    actual.port = port;
    bound_ = actual.text();
  }
  if (::listen(fd_, kBacklog) != 0) {
    const int error = errno;
    ::close(fd_);
    if (!unix_path_.empty()) ::unlink(unix_path_.c_str());
    fail(address, "listen", error);
  }
}

std::shared_ptr<ListenSocket> ListenSocket::shared(const ListenAddress& address) {
  static std::mutex mutex;
  static std::map<std::string, std::weak_ptr<ListenSocket>> listening;
  if (address.kind == ListenAddress::Kind::Tcp && address.port == 0) return std::make_shared<ListenSocket>(address);
  std::lock_guard lock(mutex);
  std::weak_ptr<ListenSocket>& slot = listening[address.text()];
  std::shared_ptr<ListenSocket> socket = slot.lock();
  if (!socket) {
    socket = std::make_shared<ListenSocket>(address);
    slot = socket;
  }
  return socket;
}

ListenSocket::~ListenSocket() {
  if (owned_ && fd_ >= 0) ::close(fd_);
  if (!unix_path_.empty()) ::unlink(unix_path_.c_str());
}

}  // namespace arpipe
