// PhysicsError: a rigid-body or collider spec (or the world's settings) that the physics cannot
// take; what() names the body or collider (index and name), the field and what was expected.
#pragma once

#include <stdexcept>

namespace arpipe {

// An std::invalid_argument, so callers that check specs generically can catch that.
class PhysicsError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

}  // namespace arpipe
