#include "capture/sinks/write_outage.h"

#include "core/log.h"
#include "core/pipeline/monotonic_clock.h"

namespace arpipe {

WriteOutage::WriteOutage(std::string target, std::string kept, std::function<int64_t()> now)
    : target_(std::move(target)), kept_(std::move(kept)), now_(now ? std::move(now) : monotonic_now_ns) {}

void WriteOutage::failed(uint64_t frame_index, std::string_view why) noexcept {
  ++failures_;
  if (active_) {
    ++lost_now_;
    return;
  }
  active_ = true;
  lost_now_ = 1;
  first_lost_ = frame_index;
  try {
    const int64_t now = now_();
    active_logged_ = !logged_any_ || now - last_logged_start_ns_ >= kQuietNs;
    if (!active_logged_) return;
    logged_any_ = true;
    last_logged_start_ns_ = now;
    std::string earlier;
    if (unlogged_outages_ > 0)
      earlier = fmt::format(" ({} shorter outages since the last message lost {} frames and were only counted)",
                            unlogged_outages_, unlogged_frames_);
    unlogged_outages_ = unlogged_frames_ = 0;
    log::error("{}: cannot write frame {}: {}; {}. Later frames are retried, and failures are only counted until "
               "writing resumes{}",
               target_, frame_index, why, kept_, earlier);
  } catch (...) {  // logging must not take the sink down
  }
}

void WriteOutage::succeeded(uint64_t frame_index) noexcept {
  if (!active_) return;
  active_ = false;
  if (!active_logged_) {
    ++unlogged_outages_;
    unlogged_frames_ += lost_now_;
    return;
  }
  try {
    log::notice("{}: writing resumed at frame {}; {} frames were lost (from frame {})", target_, frame_index,
                lost_now_, first_lost_);
  } catch (...) {
  }
}

void WriteOutage::report_at_end() noexcept {
  try {
    if (active_ && active_logged_) {
      log::error("{}: the run ends with writing still failing; {} frames were lost (from frame {})", target_,
                 lost_now_, first_lost_);
    } else if (active_) {
      ++unlogged_outages_;
      unlogged_frames_ += lost_now_;
    }
    if (unlogged_outages_ > 0)
      log::error("{}: {} more outages since the last message lost {} frames in all", target_, unlogged_outages_,
                 unlogged_frames_);
  } catch (...) {
  }
  active_ = false;
  unlogged_outages_ = unlogged_frames_ = 0;
}

}  // namespace arpipe
