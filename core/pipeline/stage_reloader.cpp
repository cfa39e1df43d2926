// Reloads the stages' config and the sinks while frames flow (see stage_reloader.h).
#include "core/pipeline/stage_reloader.h"

#include <fmt/format.h>

#include <exception>

namespace arpipe {

struct StageReloader::Request {
  enum class State { Waiting, Claimed, Answered };
  Loaded loaded;
  State state = State::Waiting;
  std::string error;  // the answer; empty: accepted
};

StageReloader::StageReloader(std::vector<std::pair<std::string, StageAssetLoader>> loaders,
                             std::vector<SinkSlot> sinks, Config running)
    : loaders_(std::move(loaders)), sink_slots_(std::move(sinks)), running_(std::move(running)) {}

uint64_t StageReloader::new_ticket() {
  std::lock_guard lock(mutex_);
  supersede_pending_locked();
  return ++newest_ticket_;
}

void StageReloader::supersede_pending_locked() {
  if (!pending_) return;
  pending_->state = Request::State::Answered;
  pending_->error = kSuperseded;
  pending_.reset();
  answered_.notify_all();
}

std::string StageReloader::refusal_locked(uint64_t ticket) const {
  if (closed_) return closed_why_;
  if (ticket != newest_ticket_) return kSuperseded;
  return {};
}

bool StageReloader::make_sinks(uint64_t ticket, const Config& running, const Config& config, Loaded& loaded,
                               std::string& error) {
  for (const SinkSlot& slot : sink_slots_) {
    if (slot.same(running, config)) continue;
    {
      std::lock_guard lock(mutex_);
      error = refusal_locked(ticket);
      if (!error.empty()) return false;
    }
    if (!loaded.sinks) loaded.sinks = std::make_shared<SinkSwap>();
    try {
      loaded.sinks->sinks.emplace_back(slot.key, slot.make(config));
    } catch (const std::exception& e) {
      error = fmt::format("{}: {}", slot.key, e.what());
      return false;  // the sinks made so far close unused: their outputs stay as they were
    }
  }
  return true;
}

bool StageReloader::reconfigure(uint64_t ticket, const Config& config, std::string& error,
                                std::chrono::milliseconds boundary_timeout, Config* replaced) {
  auto request = std::make_shared<Request>();
  request->loaded.config = config;
  for (const auto& [stage, loader] : loaders_) {
    {
      std::lock_guard lock(mutex_);
      error = refusal_locked(ticket);
      if (!error.empty()) return false;  // stop loading what can no longer be applied
    }
    try {
      request->loaded.assets.push_back(loader ? loader(config) : nullptr);
    } catch (const std::exception& e) {
      error = fmt::format("stage {}: {}", stage, e.what());
      return false;
    }
  }

  // The sinks are compared with the config this reload will replace. Once this ticket is the
  // newest, only a reload the processing thread has already claimed can still change that config:
  // its answer is waited for (swapping in is GPU uploads only, so it comes soon).
  Config running;
  {
    std::unique_lock lock(mutex_);
    answered_.wait(lock, [&] { return !claimed_; });
    error = refusal_locked(ticket);
    if (!error.empty()) return false;
    running = running_;
  }
  if (!make_sinks(ticket, running, config, request->loaded, error)) return false;

  std::unique_lock lock(mutex_);
  error = refusal_locked(ticket);
  if (!error.empty()) return false;
  supersede_pending_locked();
  pending_ = request;
  answered_.wait_for(lock, boundary_timeout, [&] { return request->state != Request::State::Waiting; });
  if (request->state == Request::State::Waiting) {
    // Refused under the lock that claim() takes: the processing thread can no longer pick it up.
    pending_.reset();
    request->state = Request::State::Answered;
    error = fmt::format("the pipeline reached no frame boundary within {} s (no frames arriving?)",
                        double(boundary_timeout.count()) / 1000.0);
    return false;
  }
  // Claimed: swapping in is GPU uploads only, so the answer comes soon.
  answered_.wait(lock, [&] { return request->state == Request::State::Answered; });
  error = request->error;
  if (error.empty() && replaced) *replaced = std::move(running);
  return error.empty();
}

std::shared_ptr<StageReloader::Request> StageReloader::claim() {
  std::lock_guard lock(mutex_);
  std::shared_ptr<Request> request;
  request.swap(pending_);
  if (request) {
    request->state = Request::State::Claimed;
    claimed_ = true;
  }
  return request;
}

const StageReloader::Loaded& StageReloader::loaded(const Request& request) const { return request.loaded; }

void StageReloader::finish(const std::shared_ptr<Request>& request, const std::string& error) {
  std::lock_guard lock(mutex_);
  request->error = error;
  request->state = Request::State::Answered;
  if (error.empty()) running_ = request->loaded.config;
  claimed_ = false;
  answered_.notify_all();
}

void StageReloader::close(const std::string& why) {
  std::lock_guard lock(mutex_);
  closed_ = true;
  closed_why_ = why;
  if (pending_) {
    pending_->state = Request::State::Answered;
    pending_->error = why;
    pending_.reset();
    answered_.notify_all();
  }
}

}  // namespace arpipe
