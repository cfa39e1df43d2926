// Where a network sink listens, parsed from its config text: "HOST:PORT" (IPv4 or [IPv6]), a Unix
// socket path, or "systemd" (a socket systemd passes). Parsing only; capture/sinks/http binds it.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace arpipe {

struct ListenAddress {
  enum class Kind { Tcp, Unix, Systemd };
  Kind kind = Kind::Tcp;
  std::string host;  // Tcp: a numeric IPv4 or IPv6 address (no brackets), or "localhost"
  uint16_t port = 0;  // Tcp: 0 lets the kernel choose (tests)
  std::string path;  // Unix: the socket's path
  std::string text() const;  // as the config writes it
};

// nullopt when the text is none of the three forms; `why` then says what is wrong.
std::optional<ListenAddress> parse_listen_address(std::string_view text, std::string& why);

}  // namespace arpipe
