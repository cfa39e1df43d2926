// Keeps a measured light estimate while each new measurement stays within the measurement's own
// noise of it. A light probe measures a still lamp slightly differently every frame (on
// probe-indoor its place by 0.5-1 mm, its strength by up to 2 %): handed on as measured, the
// virtual shadows shimmer with that noise, and everything the render stage keys on the light (the
// shadow map, the ground catcher's bake, the whole layer of a still camera) is drawn anew each
// frame. Kept, a still lamp gives the same light every frame, bit for bit; a lamp that moves or
// changes by more than the band is followed at once (the band is about the kept estimate, so a
// slow drift is followed once it has drifted that far).
#pragma once

#include <optional>

#include "core/geometry/vec.h"
#include "core/light/light_estimate.h"

namespace arpipe {

struct LightHoldBand {
  double direction_rad = 0;    // each light's direction (a lamp's as seen from `centre`)
  double relative_change = 0;  // each light's irradiance and angular size, the ambient SH as a whole (RGB norms)
  bool enabled() const { return direction_rad > 0 || relative_change > 0; }
};

class LightHold {
 public:
  // centre: where a lamp's direction is seen from (the probe's centre), so that its band is the
  // probe's angle however far the lamp was placed.
  explicit LightHold(LightHoldBand band = {}, Vec3 centre = {0, 0, 0}) : band_(band), centre_(centre) {}

  // What to hand on for this frame's measurement:
  //   - Estimated, within the band of the kept estimate: the kept one, its frames_kept counting on;
  //   - Estimated otherwise: the measurement, kept from now on;
  //   - Held (nothing measurable on this frame): the kept lights and ambient, with the
  //     measurement's state, note and frames_since_measured;
  //   - NoDirect or None: the measurement, and nothing kept.
  // With the band off, every measurement as it is.
  LightEstimate apply(const LightEstimate& measured);

  // Whether b lies within the band of a (same lights, each within the band; ambient too).
  bool within_band(const LightEstimate& a, const LightEstimate& b) const;

 private:
  LightHoldBand band_;
  Vec3 centre_;
  std::optional<LightEstimate> kept_;
};

}  // namespace arpipe
