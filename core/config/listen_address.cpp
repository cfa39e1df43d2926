#include "core/config/listen_address.h"

#include <arpa/inet.h>
#include <sys/un.h>

#include <charconv>

#include <fmt/format.h>

namespace arpipe {

std::string ListenAddress::text() const {
  switch (kind) {
    case Kind::Systemd: return "systemd";
    case Kind::Unix: return path;
    case Kind::Tcp: break;
  }
  return host.find(':') != std::string::npos ? fmt::format("[{}]:{}", host, port) : fmt::format("{}:{}", host, port);
}

std::optional<ListenAddress> parse_listen_address(std::string_view text, std::string& why) {
  ListenAddress address;
  if (text == "systemd") {
    address.kind = ListenAddress::Kind::Systemd;
    return address;
  }
  if (text.starts_with('/') || text.starts_with("./")) {
    // sun_path holds the path and its terminating NUL.
    if (text.size() >= sizeof(sockaddr_un{}.sun_path)) {
      why = fmt::format("a Unix socket path of at most {} bytes", sizeof(sockaddr_un{}.sun_path) - 1);
      return std::nullopt;
    }
    address.kind = ListenAddress::Kind::Unix;
    address.path = std::string(text);
    return address;
  }
  const size_t colon = text.rfind(':');
  if (colon == std::string_view::npos) {
    why = "\"HOST:PORT\", a Unix socket path starting with \"/\" or \"./\", or \"systemd\"";
    return std::nullopt;
  }
  std::string_view host = text.substr(0, colon), port = text.substr(colon + 1);
  if (host.starts_with('[') && host.ends_with(']')) host = host.substr(1, host.size() - 2);
  unsigned value = 0;
  const auto [end, error] = std::from_chars(port.data(), port.data() + port.size(), value);
  if (port.empty() || error != std::errc() || end != port.data() + port.size() || value > 65535) {
    why = "a port number in [0, 65535] after the last \":\"";
    return std::nullopt;
  }
  const std::string host_text(host);
  in6_addr v6{};
  in_addr v4{};
  if (host_text != "localhost" && inet_pton(AF_INET, host_text.c_str(), &v4) != 1 &&
      inet_pton(AF_INET6, host_text.c_str(), &v6) != 1) {
    why = "a numeric IPv4 address, an IPv6 address in brackets, or localhost before the port";
    return std::nullopt;
  }
  address.host = host_text == "localhost" ? "127.0.0.1" : host_text;
  address.port = static_cast<uint16_t>(value);
  return address;
}

}  // namespace arpipe
