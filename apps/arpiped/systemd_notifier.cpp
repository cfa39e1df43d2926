#include "apps/arpiped/systemd_notifier.h"

#include <systemd/sd-daemon.h>

namespace arpipe {

SystemdNotifier::SystemdNotifier() {
  uint64_t usec = 0;
  if (sd_watchdog_enabled(0, &usec) > 0) watchdog_interval_ns_ = int64_t(usec) * 1000;
}

void SystemdNotifier::ready() { sd_notify(0, "READY=1"); }
void SystemdNotifier::reloading() { sd_notify(0, "RELOADING=1"); }
void SystemdNotifier::stopping() { sd_notify(0, "STOPPING=1"); }
void SystemdNotifier::status(const std::string& text) { sd_notifyf(0, "STATUS=%s", text.c_str()); }
void SystemdNotifier::watchdog_ping() { sd_notify(0, "WATCHDOG=1"); }

}  // namespace arpipe
