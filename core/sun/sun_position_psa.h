// The sun's position by the PSA algorithm (Blanco-Muriel et al., "Computing the solar vector",
// Solar Energy 70(5) 2001), as seed 001 uses it: UT in, parallax corrected, no refraction.
#pragma once

#include "core/sun/civil_time.h"

namespace arpipe {

struct PsaResult {
  double zenith_deg = 0;   // topocentric (parallax-corrected), without refraction
  double azimuth_deg = 0;  // from north, clockwise (east positive), 0..360
  double declination_deg = 0;
  double hour_angle_deg = 0;
};

// time is taken as UT (UT1 ≈ UTC to within 0.9 s). Inputs are not checked here beyond what the
// caller's config boundary already did (latitude −90..90, longitude east positive).
PsaResult psa_sun_position(const UtcInstant& time, double latitude_deg, double longitude_deg);

}  // namespace arpipe
