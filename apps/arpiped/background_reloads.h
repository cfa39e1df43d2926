// arpiped's SIGHUP reloads, each on a thread of its own: the main thread keeps answering signals and
// pinging the watchdog, and the processing thread keeps drawing frames, while a config and its
// assets load. A newer SIGHUP supersedes a reload still loading; a refused reload is never applied.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "apps/arpiped/daemon.h"
#include "apps/arpiped/systemd_notifier.h"
#include "core/config/config.h"
#include "core/pipeline/stage_reloader.h"

namespace arpipe {

class BackgroundReloads {
 public:
  // started: the config the source, queues and GL context were made from (their keys need a restart).
  BackgroundReloads(const DaemonOptions& options, const Config& started, std::shared_ptr<StageReloader> reloader,
                    SystemdNotifier systemd);

  // How a reload ended: applied (and what changed) or not (and why).
  using Done = std::function<void(bool applied, const std::string& message)>;

  // Reloads the config file on a new thread (RELOADING=1 now, READY=1 once the newest reload is
  // answered). A change to a key that needs a restart refuses the whole reload, naming the key;
  // everything else is applied (stages, light source, sinks). Logs "reload applied: " and what
  // changed, "reload refused: " and why, or that a newer reload superseded it.
  // why: what asked ("SIGHUP", "arpipe ctl set"). extra: assignments (as --set takes them) on top
  // of the command line's and of those earlier applied ones; applied, they stay for every later
  // reload until the daemon restarts. done: called on the reload's thread once it is answered.
  void start(const std::string& why = "SIGHUP", std::vector<std::string> extra = {}, Done done = {});
  // Whether a reload thread is still running (stuck on a file, or baking): the daemon then leaves
  // with _exit rather than unwind what that thread may still touch.
  bool any_running() const;

 private:
  struct Shared;  // what the (detached) reload threads share; outlives this object when one is stuck
  // One reload, on its own thread.
  static void reload(const std::shared_ptr<Shared>& s, uint64_t ticket, const std::vector<std::string>& extra,
                     const Done& done);
  std::shared_ptr<Shared> shared_;
};

}  // namespace arpipe
