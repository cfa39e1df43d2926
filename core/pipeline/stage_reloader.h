// Reloads the stages' config and the sinks while frames flow: the slow, GL-free loading (and the
// opening of new outputs) runs on the thread that asks for the reload; the processing thread only
// swaps the loaded result in at a frame boundary, and hands the new sinks on to the sink thread.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "core/config/config.h"
#include "core/pipeline/sink_slot.h"
#include "core/pipeline/stage.h"

namespace arpipe {

// Shared (std::shared_ptr) by the runner and the threads that reload: a reload stuck on a file may
// outlive the runner, and then finds the reloader closed.
class StageReloader {
 public:
  // A config with what every stage's loader made of it, in the stages' order, and the sinks whose
  // part of the config changed (null when none did).
  struct Loaded {
    Config config;
    std::vector<std::shared_ptr<const StageAssets>> assets;
    std::shared_ptr<SinkSwap> sinks;
  };
  struct Request;  // one reload, from its loading to its answer
  // The answer of a reload that a newer ticket superseded.
  static constexpr const char* kSuperseded = "superseded by a newer reload";

  // One loader per stage (an empty function where the stage loads nothing), with the stage's name;
  // the sinks that reloads may replace; the config running now.
  StageReloader(std::vector<std::pair<std::string, StageAssetLoader>> loaders, std::vector<SinkSlot> sinks,
                Config running);

  // Taken when the reload is asked for (the SIGHUP), before anything is read: a newer ticket
  // supersedes every older reload, whether it is still loading or waiting for a frame boundary,
  // and a superseded reload is never applied.
  uint64_t new_ticket();

  // Loads `config` on the calling thread (no time limit: the running config keeps going meanwhile)
  // and makes the sinks whose part of it differs from the running config's, then waits up to
  // boundary_timeout for the processing thread to take it at a frame boundary and for its answer.
  // False, with the reason, when a loader throws, a sink cannot be made, a stage refuses the config,
  // a newer ticket superseded this one, no frame boundary came in time, or the stream ended. A
  // reload answered false is never applied afterwards. Accepted: `replaced` (if given) receives the
  // config that was running until then.
  bool reconfigure(uint64_t ticket, const Config& config, std::string& error,
                   std::chrono::milliseconds boundary_timeout, Config* replaced = nullptr);

  // The processing thread, between frames: the loaded reload waiting for it, if any. From here on
  // the reload can no longer time out; the processing thread must answer it with finish() (an
  // empty error: accepted, and its config is the running one from then on).
  std::shared_ptr<Request> claim();
  const Loaded& loaded(const Request& request) const;
  void finish(const std::shared_ptr<Request>& request, const std::string& error);

  // No more reloads (the stream ended): answers one still waiting and refuses later ones with `why`.
  void close(const std::string& why);

 private:
  // Why a reload with this ticket cannot go on, or empty. Needs mutex_.
  std::string refusal_locked(uint64_t ticket) const;
  void supersede_pending_locked();
  // The sinks of `config` whose part differs from `running`'s; false with the reason when one cannot
  // be made or the ticket was superseded meanwhile.
  bool make_sinks(uint64_t ticket, const Config& running, const Config& config, Loaded& loaded, std::string& error);

  const std::vector<std::pair<std::string, StageAssetLoader>> loaders_;
  const std::vector<SinkSlot> sink_slots_;
  std::mutex mutex_;
  std::condition_variable answered_;
  uint64_t newest_ticket_ = 0;
  std::shared_ptr<Request> pending_;  // loaded, waiting for a frame boundary
  bool claimed_ = false;              // a request is being swapped in by the processing thread
  Config running_;                    // the config the stages and sinks run with
  bool closed_ = false;
  std::string closed_why_;
};

}  // namespace arpipe
