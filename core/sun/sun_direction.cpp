// Sun direction into ENU and the anchor frame. GeographicLib's Math gives exact degree trig
// (sincosd reduces the angle exactly, so 90° gives exactly 0 and 1); LocalCartesian is not needed:
// a direction at the observer is already in the observer's ENU.
#include "core/sun/sun_direction.h"

#include <GeographicLib/Math.hpp>

namespace arpipe {

using GeographicLib::Math;

Vec3 sun_direction_enu(double zenith_deg, double azimuth_deg) {
  double sin_z = 0, cos_z = 0, sin_a = 0, cos_a = 0;
  Math::sincosd(zenith_deg, sin_z, cos_z);  // cos e = sin Z, sin e = cos Z
  Math::sincosd(azimuth_deg, sin_a, cos_a);
  return normalized(Vec3{sin_a * sin_z, cos_a * sin_z, cos_z});
}

Mat3 R_world_enu(const AnchorHeading& heading) {
  double s = 0, c = 0;
  Math::sincosd(Math::AngNormalize(heading.true_heading_deg()), s, c);
  // world +y = the anchor's heading psi: (sin psi, cos psi, 0); world +x = psi + 90° clockwise:
  // (cos psi, −sin psi, 0); world +z = up.
  return {{{c, -s, 0}, {s, c, 0}, {0, 0, 1}}};
}

SunInWorld sun_in_world(double apparent_zenith_deg, double geometric_zenith_deg, double azimuth_deg,
                        const AnchorHeading& heading) {
  SunInWorld out;
  out.towards_sun_world = mat_mul(R_world_enu(heading), sun_direction_enu(apparent_zenith_deg, azimuth_deg));
  out.elevation_deg = 90.0 - apparent_zenith_deg;
  out.elevation_geometric_deg = 90.0 - geometric_zenith_deg;
  const double az = Math::AngNormalize(azimuth_deg);
  out.azimuth_deg = az < 0 ? az + 360.0 : az;
  out.above_horizon = out.elevation_deg > -kSunAngularRadiusDeg;
  return out;
}

}  // namespace arpipe
