// The sun's topocentric position by NREL's Solar Position Algorithm (Reda & Andreas, Solar Energy
// 76(5) 2004 and NREL/TP-560-34302 rev. 2008), implemented from the paper: ±0.0003° for −2000..6000.
#pragma once

#include "core/sun/civil_time.h"

namespace arpipe {

struct SpaInput {
  UtcInstant time;                 // UTC
  double delta_ut1_s = 0.0;        // UT1 − UTC, |·| < 1 s (IERS bulletin A); 0 if unknown
  double delta_t_s = 69.2;         // TT − UT1 (delta_t_estimate_s() if unknown), |·| <= 8000 s
  double latitude_deg = 0.0;       // −90..90, north positive
  double longitude_deg = 0.0;      // −180..180, east positive
  double elevation_m = 0.0;        // above sea level, > −6'500'000
  double pressure_mbar = 1013.25;  // annual mean local pressure, 0..5000
  double temperature_c = 15.0;     // annual mean local temperature, −273..6000
  double atmos_refract_deg = 0.5667;  // refraction at sunrise/sunset, |·| <= 5
};

// Angles in degrees. Names follow the paper (its section 3 and table A5.1).
struct SpaResult {
  double jd = 0, jde = 0;          // Julian Day (UT1) and Julian Ephemeris Day (TT)
  double jc = 0, jce = 0, jme = 0; // Julian century, ephemeris century, ephemeris millennium
  double L = 0, B = 0, R = 0;      // heliocentric longitude, latitude (deg), radius vector (AU)
  double theta = 0, beta = 0;      // geocentric longitude and latitude
  double x0 = 0, x1 = 0, x2 = 0, x3 = 0, x4 = 0;  // D, M, M', F, Ω (nutation arguments)
  double del_psi = 0, del_epsilon = 0;            // nutation in longitude and obliquity
  double epsilon0 = 0;             // mean obliquity (arcsec)
  double epsilon = 0;              // true obliquity
  double del_tau = 0;              // aberration correction
  double lamda = 0;                // apparent sun longitude
  double nu0 = 0, nu = 0;          // mean and apparent sidereal time at Greenwich
  double alpha = 0, delta = 0;     // geocentric right ascension and declination
  double h = 0;                    // observer local hour angle
  double xi = 0;                   // equatorial horizontal parallax of the sun
  double del_alpha = 0;            // parallax in right ascension
  double delta_prime = 0;          // topocentric declination
  double alpha_prime = 0;          // topocentric right ascension
  double h_prime = 0;              // topocentric local hour angle
  double e0 = 0;                   // topocentric elevation without refraction
  double del_e = 0;                // atmospheric refraction correction (0 below −(0.26667° + atmos_refract))
  double e = 0;                    // topocentric elevation with refraction (apparent)
  double zenith = 0;               // topocentric zenith with refraction: 90 − e
  double zenith_geometric = 0;     // 90 − e0
  double azimuth_astro = 0;        // westward from south
  double azimuth = 0;              // eastward from north, 0..360
};

// Throws std::invalid_argument naming the value and the allowed range when an input is not finite
// or out of range (year −2000..6000, latitude, longitude, ΔT, ΔUT1, pressure, temperature ...).
SpaResult spa_sun_position(const SpaInput& in);

// SPA's refraction correction (step 3.14.2), degrees, for a geometric elevation e0: 0 when the
// sun's upper limb is below the refracted horizon (e0 < −(0.26667° + atmos_refract)).
double spa_refraction_deg(double e0_deg, double pressure_mbar, double temperature_c, double atmos_refract_deg);

// The same check alone (the config boundary calls it once).
void validate_spa_input(const SpaInput& in);

}  // namespace arpipe
