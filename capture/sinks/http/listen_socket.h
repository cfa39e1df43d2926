// The listening socket of a network sink, made from its ListenAddress: bound and listening for
// TCP and Unix sockets, or taken from systemd (socket activation).
#pragma once

#include <memory>
#include <string>

#include "core/config/listen_address.h"

namespace arpipe {

class ListenSocket {
 public:
  // Throws std::runtime_error naming the address when it cannot be bound (in use, no permission)
  // or systemd passed no stream socket. A Unix socket's stale file from an earlier run is replaced;
  // the new one is made group-writable and no more (the service's group may connect).
  explicit ListenSocket(const ListenAddress& address);
  ~ListenSocket();
  ListenSocket(const ListenSocket&) = delete;
  ListenSocket& operator=(const ListenSocket&) = delete;

  // The socket already listening on this address in this process, or a new one: a reload that
  // makes a new HTTP sink on the same address takes over the socket (no refused bind, no
  // connection refused between the two). Port 0 always makes a new one.
  static std::shared_ptr<ListenSocket> shared(const ListenAddress& address);

  int fd() const { return fd_; }
  // Where it listens, the kernel's chosen port included ("127.0.0.1:40123", "/run/arpiped/http.sock").
  const std::string& bound() const { return bound_; }

 private:
  int fd_ = -1;
  std::string bound_;
  std::string unix_path_;  // removed again on destruction
  bool owned_ = true;      // false for systemd's socket, which systemd keeps
};

}  // namespace arpipe
