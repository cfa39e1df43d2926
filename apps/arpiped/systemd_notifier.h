// sd_notify for arpiped: READY, RELOADING, STOPPING, STATUS and the watchdog keep-alive.
// Outside systemd (no NOTIFY_SOCKET) every call is a no-op.
#pragma once

#include <cstdint>
#include <string>

namespace arpipe {

class SystemdNotifier {
 public:
  SystemdNotifier();
  void ready();
  void reloading();
  void stopping();
  void status(const std::string& text);
  void watchdog_ping();
  // Watchdog interval systemd asked for (WatchdogSec), 0 when there is none.
  int64_t watchdog_interval_ns() const { return watchdog_interval_ns_; }

 private:
  int64_t watchdog_interval_ns_ = 0;
};

}  // namespace arpipe
