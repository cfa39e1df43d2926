// PSA exactly as transcribed in notes/seeds/001_004_shadows.md §2.2 from dissertation 001's
// Appendix A (http://www.psa.es/sdg/sunpos.htm). The OCR of 001 garbles the Julian Day line
// ("(367*(udtTime.iMonth + liAux1)/100))/4"); the seed's fix, used here, is the canonical
// "(367*(iMonth - 2 - 12*liAux1))/12 - (3*((iYear + 4900 + liAux1)/100))/4".
#include "core/sun/sun_position_psa.h"

#include <cmath>

namespace arpipe {

PsaResult psa_sun_position(const UtcInstant& time, double latitude_deg, double longitude_deg) {
  constexpr double pi = 3.14159265358979323846;
  constexpr double twopi = 2 * pi;
  constexpr double rad = pi / 180;
  constexpr double dEarthMeanRadius = 6371.01;      // km
  constexpr double dAstronomicalUnit = 149597890;  // km

  const CivilDateTime c = time.civil();
  const double dSeconds = c.second + 1e-9 * static_cast<double>(c.nanosecond);

  // Time of day in UT decimal hours, and the Julian Day (integer arithmetic, truncating division).
  const double dDecimalHours = c.hour + (c.minute + dSeconds / 60.0) / 60.0;
  const long liAux1 = (c.month - 14) / 12;
  const long liAux2 = (1461 * (c.year + 4800 + liAux1)) / 4 + (367 * (c.month - 2 - 12 * liAux1)) / 12 -
                      (3 * ((c.year + 4900 + liAux1) / 100)) / 4 + c.day - 32075;
  const double dJulianDate = static_cast<double>(liAux2) - 0.5 + dDecimalHours / 24.0;
  const double dElapsedJulianDays = dJulianDate - 2451545.0;

  // Ecliptic coordinates (radians, not range-reduced).
  const double dOmega = 2.1429 - 0.0010394594 * dElapsedJulianDays;
  const double dMeanLongitude = 4.8950630 + 0.017202791698 * dElapsedJulianDays;
  const double dMeanAnomaly = 6.2400600 + 0.0172019699 * dElapsedJulianDays;
  const double dEclipticLongitude = dMeanLongitude + 0.03341607 * std::sin(dMeanAnomaly) +
                                    0.00034894 * std::sin(2 * dMeanAnomaly) - 0.0001134 -
                                    0.0000203 * std::sin(dOmega);
  const double dEclipticObliquity = 0.4090928 - 6.2140e-9 * dElapsedJulianDays + 0.0000396 * std::cos(dOmega);

  // Celestial coordinates.
  const double dSin_EclipticLongitude = std::sin(dEclipticLongitude);
  double dY = std::cos(dEclipticObliquity) * dSin_EclipticLongitude;
  double dX = std::cos(dEclipticLongitude);
  double dRightAscension = std::atan2(dY, dX);
  if (dRightAscension < 0.0) dRightAscension += twopi;
  const double dDeclination = std::asin(std::sin(dEclipticObliquity) * dSin_EclipticLongitude);

  // Local coordinates.
  const double dGreenwichMeanSiderealTime = 6.6974243242 + 0.0657098283 * dElapsedJulianDays + dDecimalHours;
  const double dLocalMeanSiderealTime = (dGreenwichMeanSiderealTime * 15 + longitude_deg) * rad;
  const double dHourAngle = dLocalMeanSiderealTime - dRightAscension;
  const double dLatitudeInRadians = latitude_deg * rad;
  const double dCos_Latitude = std::cos(dLatitudeInRadians);
  const double dSin_Latitude = std::sin(dLatitudeInRadians);
  const double dCos_HourAngle = std::cos(dHourAngle);
  double dZenithAngle = std::acos(dCos_Latitude * dCos_HourAngle * std::cos(dDeclination) +
                                  std::sin(dDeclination) * dSin_Latitude);
  dY = -std::sin(dHourAngle);
  dX = std::tan(dDeclination) * dCos_Latitude - dSin_Latitude * dCos_HourAngle;
  double dAzimuth = std::atan2(dY, dX);
  if (dAzimuth < 0.0) dAzimuth += twopi;
  dAzimuth /= rad;

  // Parallax correction.
  const double dParallax = (dEarthMeanRadius / dAstronomicalUnit) * std::sin(dZenithAngle);
  dZenithAngle = (dZenithAngle + dParallax) / rad;

  PsaResult r;
  r.zenith_deg = dZenithAngle;
  r.azimuth_deg = dAzimuth;
  r.declination_deg = dDeclination / rad;
  r.hour_angle_deg = std::remainder(dHourAngle / rad, 360.0);
  return r;
}

}  // namespace arpipe
