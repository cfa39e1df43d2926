// The faults a served device injects (unplug, stall, drop, error buffer, EAGAIN storm, EIO), each
// firing once when its recording frame is about to fall due; docs/V4L2_STANDIN.md lists them.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/config/choice_names.h"

namespace arpipe::standin {

enum class FaultKind { Unplug, Stall, Drop, ErrorBuffer, Eagain, Eio };
inline constexpr ChoiceName<FaultKind> kFaultKindNames[] = {
    {"unplug", FaultKind::Unplug}, {"stall", FaultKind::Stall},   {"drop", FaultKind::Drop},
    {"error_buffer", FaultKind::ErrorBuffer}, {"eagain", FaultKind::Eagain}, {"eio", FaultKind::Eio}};

struct Fault {
  size_t frame = 0;  // 0-based recording frame
  FaultKind kind = FaultKind::Drop;
  int64_t replug_after_ns = -1;  // unplug: < 0 never comes back
  int64_t duration_ns = 0;       // stall
  uint32_t count = 1;            // drop: frames skipped; eagain: spurious wake-ups
  std::string place;             // "file:line:column" of the [[device.fault]] table
};

// The faults of one device and which have fired (each fires once per loaded configuration).
class FaultPlan {
 public:
  explicit FaultPlan(std::vector<Fault> faults) : faults_(std::move(faults)), fired_(faults_.size(), false) {}
  // The faults of recording frame `frame` that have not fired yet, in file order; marks them fired.
  std::vector<Fault> take(size_t frame);
  const std::vector<Fault>& faults() const { return faults_; }

 private:
  std::vector<Fault> faults_;
  std::vector<bool> fired_;
};

}  // namespace arpipe::standin
