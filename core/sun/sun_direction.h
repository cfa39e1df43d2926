// The direction towards the sun: from (zenith, azimuth) into local East-North-Up, then into the
// arpipe world (anchor) frame given the anchor's heading from true north.
#pragma once

#include "core/geometry/vec.h"

namespace arpipe {

// The sun's angular radius used for "above the horizon" (SPA's 0.26667°).
constexpr double kSunAngularRadiusDeg = 0.26667;

// How the anchor lies: face up (its +z = up), its +y axis (the tag's top edge) pointing at
// heading_deg, a bearing from TRUE north, clockwise (east positive). A heading measured with a
// compass is magnetic: then declination_deg (east positive) is added, true = magnetic + declination.
struct AnchorHeading {
  double heading_deg = 0.0;
  double declination_deg = 0.0;
  double true_heading_deg() const { return heading_deg + declination_deg; }
};

struct SunInWorld {
  Vec3 towards_sun_world{0, 0, 1};     // unit, world (anchor) frame, from the apparent position
  double elevation_deg = 0;            // apparent (refracted), of the sun's centre
  double elevation_geometric_deg = 0;  // without refraction
  double azimuth_deg = 0;              // from true north, clockwise
  // Direct sunlight exists: the upper limb is above the horizon, i.e. the apparent elevation of the
  // centre is > −kSunAngularRadiusDeg. The shadow pass wants more (centre_above_horizon()).
  bool above_horizon = false;
  bool centre_above_horizon() const { return elevation_deg > 0.0; }
};

// Unit vector towards the sun in ENU (x east, y north, z up): (sin A cos e, cos A cos e, sin e),
// e = 90° − zenith. Exact degree trigonometry (GeographicLib::Math::sincosd).
Vec3 sun_direction_enu(double zenith_deg, double azimuth_deg);

// The rotation taking ENU directions into the world (anchor) frame: a rotation about +z (up) by
// the anchor's true heading. Rows: world x, y, z expressed in ENU.
Mat3 R_world_enu(const AnchorHeading& heading);

// Zenith and azimuth as the sun-position algorithms give them (apparent and geometric zenith).
SunInWorld sun_in_world(double apparent_zenith_deg, double geometric_zenith_deg, double azimuth_deg,
                        const AnchorHeading& heading);

}  // namespace arpipe
