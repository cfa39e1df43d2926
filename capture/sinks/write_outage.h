// A sink's write outages (full disk, reader gone), logged once each way: what failed when writing
// stops, and how many frames were lost when it works again; the failures in between are only counted.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <string_view>

namespace arpipe {

class WriteOutage {
 public:
  // An outage that starts within this time of the last one logged is only counted (a disk that
  // keeps filling and emptying would otherwise write two lines a frame); the next message counts it.
  static constexpr int64_t kQuietNs = 60'000'000'000;

  // target: the file or directory the messages name; kept: what the output still holds during an
  // outage ("the file ends at its last complete line"). now: the clock (tests give their own).
  WriteOutage(std::string target, std::string kept, std::function<int64_t()> now = {});

  // Frame frame_index could not be written; why: the error ("No space left on device").
  void failed(uint64_t frame_index, std::string_view why) noexcept;
  // Frame frame_index was written: ends an outage (and says so when its start was logged).
  void succeeded(uint64_t frame_index) noexcept;
  // At the end of the run (the sink's destructor): reports frames lost in outages that were only
  // counted, or in the one still going on.
  void report_at_end() noexcept;

  bool active() const { return active_; }
  uint64_t failures() const { return failures_; }  // frames that could not be written, in all

 private:
  std::string target_, kept_;
  std::function<int64_t()> now_;
  bool active_ = false;
  bool active_logged_ = false;         // this outage's start was logged, so its end is too
  uint64_t failures_ = 0;
  uint64_t lost_now_ = 0;              // frames lost in the outage going on
  uint64_t first_lost_ = 0;            // its first lost frame
  int64_t last_logged_start_ns_ = 0;
  bool logged_any_ = false;
  uint64_t unlogged_outages_ = 0;      // outages since the last message that were only counted
  uint64_t unlogged_frames_ = 0;       // and the frames they lost
};

}  // namespace arpipe
