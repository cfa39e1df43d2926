// ΔT = TT − UT: an estimate from Espenak & Meeus' polynomials (NASA "Five Millennium Canon of
// Solar Eclipses", 2006), for when the user gives no measured value.
#pragma once

namespace arpipe {

// ΔT in seconds for a decimal year (2026.5 = mid 2026). Valid −1999..3000 as an estimate; the
// polynomials are fits to measurements up to 2005 and extrapolations after that (in 2026 they give
// about 75 s where IERS measures about 69 s: an error that moves the sun by ~3e-6 degrees,
// since SPA uses ΔT only for the ephemeris; the Earth's rotation comes from UT1).
double delta_t_estimate_s(double decimal_year);

}  // namespace arpipe
