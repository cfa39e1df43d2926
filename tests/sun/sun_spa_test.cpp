// SPA against NREL's published test case (NREL/TP-560-34302, table A5.1 / spa_tester.c output,
// transcribed in notes reference calib_track_sun.md §4.1), input validation, and the place and
// time that put the sun where configs/sim/sun-outdoor.toml has it.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "core/sun/civil_time.h"
#include "core/sun/delta_t.h"
#include "core/sun/sun_position_spa.h"

namespace arpipe {
namespace {

SpaInput nrel_test_input() {
  SpaInput in;
  in.time = UtcInstant::parse("2003-10-17T12:30:30-07:00");  // 12:30:30 local, timezone −7
  in.delta_ut1_s = 0;
  in.delta_t_s = 67;
  in.longitude_deg = -105.1786;
  in.latitude_deg = 39.742476;
  in.elevation_m = 1830.14;
  in.pressure_mbar = 820;
  in.temperature_c = 11;
  in.atmos_refract_deg = 0.5667;
  return in;
}

double angle_diff(double a, double b) { return std::remainder(a - b, 360.0); }

TEST(SunSpa, NrelTestCaseZenithAndAzimuth) {
  const SpaResult r = spa_sun_position(nrel_test_input());
  // The published values carry 6 decimals; the issue asks for 0.0001°.
  EXPECT_NEAR(r.zenith, 50.111622, 1e-4);
  EXPECT_NEAR(angle_diff(r.azimuth, 194.340241), 0.0, 1e-4);
  // And at the printed precision (half a unit of the last printed digit).
  EXPECT_NEAR(r.zenith, 50.111622, 5e-7);
  EXPECT_NEAR(r.azimuth, 194.340241, 5e-7);
}

TEST(SunSpa, NrelTestCaseIntermediates) {
  const SpaResult r = spa_sun_position(nrel_test_input());
  // Tolerances: half a unit in the last digit that the report prints.
  EXPECT_NEAR(r.jd, 2452930.312847, 5e-7);
  EXPECT_NEAR(r.L, 2.401826e+01, 5e-6);
  EXPECT_NEAR(r.B, -1.011219e-04, 5e-11);
  EXPECT_NEAR(r.R, 0.996542, 5e-7);
  EXPECT_NEAR(r.h, 11.105902, 5e-7);
  EXPECT_NEAR(r.del_psi, -3.998404e-03, 5e-10);
  EXPECT_NEAR(r.del_epsilon, 1.666568e-03, 5e-10);
  EXPECT_NEAR(r.epsilon, 23.440465, 5e-7);
  EXPECT_NEAR(r.e0, 39.872046, 5e-7);
  EXPECT_NEAR(r.del_e, 0.016332, 5e-7);
  EXPECT_NEAR(r.e, 39.888378, 5e-7);
  EXPECT_NEAR(r.delta_prime, -9.316179, 5e-7);
  // H′ is transcribed as 11.10627 and 11.10629 in different copies of the table: 5e-5 covers both.
  EXPECT_NEAR(r.h_prime, 11.10628, 2e-5);
  EXPECT_NEAR(r.zenith, 90.0 - r.e, 1e-12);
  EXPECT_NEAR(r.zenith_geometric, 90.0 - r.e0, 1e-12);
}

TEST(SunSpa, RejectsInputsOutsideTheirRangesNamingThem) {
  const auto expect_error = [](SpaInput in, const std::string& name) {
    try {
      spa_sun_position(in);
      ADD_FAILURE() << "no error for " << name;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
    }
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  SpaInput in = nrel_test_input();
  in.latitude_deg = 95;
  expect_error(in, "latitude");
  in.latitude_deg = -90.0001;
  expect_error(in, "latitude");
  in.latitude_deg = nan;
  expect_error(in, "latitude");
  in = nrel_test_input();
  in.longitude_deg = 180.5;
  expect_error(in, "longitude");
  in.longitude_deg = -inf;
  expect_error(in, "longitude");
  in = nrel_test_input();
  in.delta_t_s = 9000;
  expect_error(in, "delta_t");
  in = nrel_test_input();
  in.delta_ut1_s = 1.0;
  expect_error(in, "delta_ut1");
  in = nrel_test_input();
  in.pressure_mbar = -1;
  expect_error(in, "pressure");
  in = nrel_test_input();
  in.temperature_c = -300;
  expect_error(in, "temperature");
  in = nrel_test_input();
  in.elevation_m = nan;
  expect_error(in, "elevation");
  in = nrel_test_input();
  in.time = UtcInstant::parse("6001-01-01T00:00:00Z");
  expect_error(in, "year");
  // The limits themselves are allowed.
  in = nrel_test_input();
  in.latitude_deg = 90;
  in.longitude_deg = -180;
  EXPECT_NO_THROW(spa_sun_position(in));
  in.time = UtcInstant::parse("6000-12-31T23:59:59Z");
  EXPECT_NO_THROW(spa_sun_position(in));
}

// configs/sim/sun-outdoor.toml puts the sun at azimuth 135° (east of true north) and apparent
// elevation 40°. This place and time (near Lisbon, found by solving SPA for latitude and time with
// the longitude fixed) gives that sun; the end-to-end sun test computes its sun from them.
TEST(SunSpa, SunOutdoorSceneTimeAndPlace) {
  SpaInput in;
  in.time = UtcInstant::parse("2026-03-17T10:33:37.24Z");
  in.latitude_deg = 38.6444;
  in.longitude_deg = -9.14;
  in.elevation_m = 100;
  in.pressure_mbar = 1013.25;
  in.temperature_c = 15;
  in.delta_t_s = delta_t_estimate_s(in.time.decimal_year());
  const SpaResult r = spa_sun_position(in);
  EXPECT_NEAR(r.azimuth, 135.0, 0.01);  // the tolerance
  EXPECT_NEAR(r.e, 40.0, 0.01);
}

TEST(SunSpa, DeltaTEstimateMatchesTabulatedValues) {
  // Espenak & Meeus' polynomials reproduce the measured ΔT they were fitted to within about 1 s
  // (their table: 1900 −2.7 s, 1950 29.1 s, 1990 56.9 s, 2000 63.8 s, 2005 64.7 s).
  EXPECT_NEAR(delta_t_estimate_s(1900.0), -2.7, 1.0);
  EXPECT_NEAR(delta_t_estimate_s(1950.0), 29.1, 1.0);
  EXPECT_NEAR(delta_t_estimate_s(1990.0), 56.9, 1.0);
  EXPECT_NEAR(delta_t_estimate_s(2000.0), 63.8, 1.0);
  EXPECT_NEAR(delta_t_estimate_s(2005.0), 64.7, 1.0);
  // Continuous at the joins of the pieces (the published pieces meet to well within 1 s).
  for (double y : {1920.0, 1941.0, 1961.0, 1986.0, 2005.0, 2050.0, 2150.0})
    EXPECT_NEAR(delta_t_estimate_s(y - 1e-9), delta_t_estimate_s(y), 1.0) << y;
}

}  // namespace
}  // namespace arpipe
