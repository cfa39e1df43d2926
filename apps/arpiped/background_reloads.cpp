// arpiped's SIGHUP reloads on threads of their own (see background_reloads.h).
#include "apps/arpiped/background_reloads.h"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <sys/resource.h>
#include <unistd.h>

#include <atomic>
#include <exception>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "apps/arpiped/reload_changes.h"
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
  std::mutex mutex;
  std::vector<std::string> applied_sets;  // from arpipe ctl, applied; kept for later reloads
};

BackgroundReloads::BackgroundReloads(const DaemonOptions& options, const Config& started,
                                     std::shared_ptr<StageReloader> reloader, SystemdNotifier systemd)
    : shared_(std::make_shared<Shared>()) {
  shared_->options = options;
  shared_->started = started;
  shared_->reloader = std::move(reloader);
  shared_->systemd = systemd;
}

void BackgroundReloads::start(const std::string& why, std::vector<std::string> extra, Done done) {
  shared_->systemd.reloading();
  // The ticket is taken now, before anything is read: it supersedes every older reload at once.
  const uint64_t ticket = shared_->reloader->new_ticket();
  const bool superseding = shared_->running.load() > 0;
  shared_->newest_ticket = ticket;
  log::info("{}: reloading {}{}", why, shared_->options.config_path.string(),
            superseding ? " (supersedes the reload still loading)" : "");
  ++shared_->running;
  std::thread([s = shared_, ticket, extra = std::move(extra), done = std::move(done)] { reload(s, ticket, extra, done); })
      .detach();
}

bool BackgroundReloads::any_running() const { return shared_->running.load() > 0; }

void BackgroundReloads::reload(const std::shared_ptr<Shared>& s, uint64_t ticket, const std::vector<std::string>& extra,
                               const Done& done) {
  // Below the pipeline's threads, and so are the bake's workers it starts (they inherit it): the
  // frames keep their share of the CPU while a reload loads.
  setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), kReloadNiceness);
  const std::string path = s->options.config_path.string();
  std::string error;
  bool accepted = false;
  std::vector<std::string> applied;
  try {
    std::vector<std::string> overrides = s->options.overrides;
    {
      std::lock_guard lock(s->mutex);
      overrides.insert(overrides.end(), s->applied_sets.begin(), s->applied_sets.end());
    }
    overrides.insert(overrides.end(), extra.begin(), extra.end());
    Config next = load_config(s->options.config_path, overrides);
    // Refused whole, before anything is loaded: applying the rest would leave a config running
    // that is neither the old one nor the file's.
    if (const std::vector<std::string> restart = keys_needing_restart(s->started, next); !restart.empty()) {
      error = fmt::format("{} {} a restart", fmt::join(restart, ", "), restart.size() == 1 ? "needs" : "need");
    } else {
      Config replaced;
      accepted = s->reloader->reconfigure(ticket, next, error, PipelineRunner::kReconfigureBoundaryTimeout, &replaced);
      if (accepted) {
        applied = changed_parts(replaced, next);
        log::set_max_level(next.pipeline.log_level);
        std::lock_guard lock(s->mutex);
        s->applied_sets.insert(s->applied_sets.end(), extra.begin(), extra.end());
      }
    }
  } catch (const std::exception& e) {
    error = e.what();
  }
  const bool newest = s->newest_ticket.load() == ticket;
  std::string message;
  if (accepted && applied.empty())
    message = "reload applied: no key changed; the stages read their files again";
  else if (accepted)
    message = fmt::format("reload applied: {}", fmt::join(applied, ", "));
  else if (error == StageReloader::kSuperseded)
    message = fmt::format("reload of {} superseded by a newer reload: not applied", path);
  else
    message = fmt::format("reload refused: {}; the running config stays", error);
  if (accepted || error == StageReloader::kSuperseded)
    log::info("{}", message);
  else
    log::error("{}", message);
  if (newest) s->systemd.ready();
  if (done) done(accepted, message);
  --s->running;  // last: the daemon may _exit from here on
}

}  // namespace arpipe
