// Reloads the stages' config while frames flow: the slow, GL-free loading runs on the thread that
// asks for the reload; the processing thread only swaps the loaded result in at a frame boundary.
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
#include "core/pipeline/stage.h"

namespace arpipe {

// Shared (std::shared_ptr) by the runner and the threads that reload: a reload stuck on a file may
// outlive the runner, and then finds the reloader closed.
class StageReloader {
 public:
  // A config with what every stage's loader made of it, in the stages' order.
  struct Loaded {
    Config config;
    std::vector<std::shared_ptr<const StageAssets>> assets;
  };
  struct Request;  // one reload, from its loading to its answer
  // The answer of a reload that a newer ticket superseded.
  static constexpr const char* kSuperseded = "superseded by a newer reload";

  // One loader per stage (an empty function where the stage loads nothing), with the stage's name.
  explicit StageReloader(std::vector<std::pair<std::string, StageAssetLoader>> loaders);

  // Taken when the reload is asked for (the SIGHUP), before anything is read: a newer ticket
  // supersedes every older reload, whether it is still loading or waiting for a frame boundary,
  // and a superseded reload is never applied.
  uint64_t new_ticket();

  // Loads `config` on the calling thread (no time limit: the running config keeps going meanwhile),
  // then waits up to boundary_timeout for the processing thread to take it at a frame boundary and
  // for its answer. False, with the reason, when a loader throws, a stage refuses the config, a
  // newer ticket superseded this one, no frame boundary came in time, or the stream ended. A
  // reload answered false is never applied afterwards.
  bool reconfigure(uint64_t ticket, const Config& config, std::string& error,
                   std::chrono::milliseconds boundary_timeout);

  // The processing thread, between frames: the loaded reload waiting for it, if any. From here on
  // the reload can no longer time out; the processing thread must answer it with finish() (an
  // empty error: accepted).
  std::shared_ptr<Request> claim();
  const Loaded& loaded(const Request& request) const;
  void finish(const std::shared_ptr<Request>& request, const std::string& error);

  // No more reloads (the stream ended): answers one still waiting and refuses later ones with `why`.
  void close(const std::string& why);

 private:
  // Why a reload with this ticket cannot go on, or empty. Needs mutex_.
  std::string refusal_locked(uint64_t ticket) const;
  void supersede_pending_locked();

  const std::vector<std::pair<std::string, StageAssetLoader>> loaders_;
  std::mutex mutex_;
  std::condition_variable answered_;
  uint64_t newest_ticket_ = 0;
  std::shared_ptr<Request> pending_;  // loaded, waiting for a frame boundary
  bool closed_ = false;
  std::string closed_why_;
};

}  // namespace arpipe
