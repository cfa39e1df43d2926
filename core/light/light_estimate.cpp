#include "core/light/light_estimate.h"

namespace arpipe {

std::string_view light_state_name(LightState state) {
  switch (state) {
    case LightState::Estimated: return "estimated";
    case LightState::Held: return "held";
    case LightState::NoDirect: return "no-direct";
    case LightState::None: return "none";
  }
  return "?";
}

}  // namespace arpipe
