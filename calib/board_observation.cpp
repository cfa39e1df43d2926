#include "calib/board_observation.h"

#include <algorithm>

namespace arpipe::calib {

int BoardObservation::seen_count() const {
  return int(std::count_if(weights.begin(), weights.end(), [](double w) { return w > 0; }));
}

}  // namespace arpipe::calib
