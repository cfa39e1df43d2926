#include "fault_plan.h"

#include <array>
#include <utility>

namespace arpipe::standin {

namespace {
constexpr std::array<std::pair<FaultKind, std::string_view>, 6> kNames{{
    {FaultKind::Unplug, "unplug"},
    {FaultKind::Stall, "stall"},
    {FaultKind::Drop, "drop"},
    {FaultKind::ErrorBuffer, "error_buffer"},
    {FaultKind::Eagain, "eagain"},
    {FaultKind::Eio, "eio"},
}};
}  // namespace

std::string_view fault_kind_name(FaultKind kind) {
  for (const auto& [k, name] : kNames)
    if (k == kind) return name;
  return "?";
}

std::optional<FaultKind> fault_kind_from_name(std::string_view name) {
  for (const auto& [k, n] : kNames)
    if (n == name) return k;
  return std::nullopt;
}

std::vector<Fault> FaultPlan::take(size_t frame) {
  std::vector<Fault> due;
  for (size_t i = 0; i < faults_.size(); ++i) {
    if (fired_[i] || faults_[i].frame != frame) continue;
    fired_[i] = true;
    due.push_back(faults_[i]);
  }
  return due;
}

}  // namespace arpipe::standin
