#include "fault_plan.h"

namespace arpipe::standin {

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
