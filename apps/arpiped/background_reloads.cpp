// arpiped's SIGHUP reloads on threads of their own (see background_reloads.h).
#include "apps/arpiped/background_reloads.h"

#include <sys/resource.h>
#include <unistd.h>

#include <atomic>
#include <exception>
#include <string>
#include <thread>

#include "apps/arpiped/log_level.h"
#include "core/log.h"
#include "core/pipeline/pipeline_runner.h"

namespace arpipe {
namespace {

constexpr int kReloadNiceness = 10;

}  // namespace

struct BackgroundReloads::Shared {
  DaemonOptions options;
  Config started;
  std::shared_ptr<StageReloader> reloader;
  SystemdNotifier systemd;
  std::atomic<uint64_t> newest_ticket{0};
  std::atomic<int> running{0};
};

BackgroundReloads::BackgroundReloads(const DaemonOptions& options, const Config& started,
                                     std::shared_ptr<StageReloader> reloader, SystemdNotifier systemd)
    : shared_(std::make_shared<Shared>()) {
  shared_->options = options;
  shared_->started = started;
  shared_->reloader = std::move(reloader);
  shared_->systemd = systemd;
}

void BackgroundReloads::start() {
  shared_->systemd.reloading();
  // The ticket is taken now, before anything is read: it supersedes every older reload at once.
  const uint64_t ticket = shared_->reloader->new_ticket();
  const bool superseding = shared_->running.load() > 0;
  shared_->newest_ticket = ticket;
  log::info("SIGHUP: reloading {}{}", shared_->options.config_path.string(),
            superseding ? " (supersedes the reload still loading)" : "");
  ++shared_->running;
  std::thread([s = shared_, ticket] { reload(s, ticket); }).detach();
}

bool BackgroundReloads::any_running() const { return shared_->running.load() > 0; }

void BackgroundReloads::reload(const std::shared_ptr<Shared>& s, uint64_t ticket) {
  // Below the pipeline's threads, and so are the bake's workers it starts (they inherit it): the
  // frames keep their share of the CPU while a reload loads.
  setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), kReloadNiceness);
  const std::string path = s->options.config_path.string();
  std::string error;
  bool accepted = false;
  try {
    Config next = load_config(s->options.config_path, s->options.overrides);
    if (next.source != s->started.source || next.pipeline.queue_depth != s->started.pipeline.queue_depth)
      log::warn("{}: source and pipeline changes take effect at the next restart; stages and lighting now", path);
    accepted = s->reloader->reconfigure(ticket, next, error, PipelineRunner::kReconfigureBoundaryTimeout);
    if (accepted) log::set_max_level(log_level_from_name(next.pipeline.log_level));
  } catch (const std::exception& e) {
    error = e.what();
  }
  const bool newest = s->newest_ticket.load() == ticket;
  if (accepted)
    log::info("reload accepted");
  else if (error == StageReloader::kSuperseded)
    log::info("reload of {} superseded by a newer SIGHUP: not applied", path);
  else
    log::error("reload refused, the running config stays: {}", error);
  if (newest) s->systemd.ready();
  --s->running;  // last: the daemon may _exit from here on
}

}  // namespace arpipe
