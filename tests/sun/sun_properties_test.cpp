// Property tests (RapidCheck) of the sun's position and direction at the awkward places: the
// poles, the date line, the horizon, midnight UTC across day/month/year/leap-day boundaries, and
// the anchor heading; plus the civil-time parsing that feeds them and the worked ENU example.
#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/geometry/vec.h"
#include "core/sun/civil_time.h"
#include "core/sun/sun_direction.h"
#include "core/sun/sun_position_psa.h"
#include "core/sun/sun_position_spa.h"

namespace arpipe {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

// A double uniformly in [lo, hi] (RapidCheck has no built-in real range).
rc::Gen<double> in_range(double lo, double hi) {
  return rc::gen::map(rc::gen::inRange<int64_t>(0, 1'000'000'001),
                      [lo, hi](int64_t k) { return lo + (hi - lo) * static_cast<double>(k) / 1e9; });
}
// Any time 1900..2100 (whole milliseconds).
rc::Gen<UtcInstant> any_time() {
  return rc::gen::map(rc::gen::inRange<int64_t>(-2'208'988'800'000, 4'102'444'800'000),
                      [](int64_t ms) { return UtcInstant::from_unix_ns(ms * 1'000'000); });
}

SpaResult spa_at(const UtcInstant& t, double lat, double lon) {
  SpaInput in;
  in.time = t;
  in.latitude_deg = lat;
  in.longitude_deg = lon;
  in.delta_t_s = 69.2;
  return spa_sun_position(in);
}

double separation_deg(const Vec3& a, const Vec3& b) { return std::atan2(norm(cross(a, b)), dot(a, b)) * kRadToDeg; }
// Continuity is checked on the geometric direction: SPA's refraction is cut off by design when the
// upper limb sinks below the refracted horizon (e0 < −0.83337°), a 0.6° step in the apparent one.
Vec3 spa_enu(const SpaResult& r) { return sun_direction_enu(r.zenith_geometric, r.azimuth); }

// --- unit vectors -------------------------------------------------------------------------------

RC_GTEST_PROP(SunProperties, DirectionsAreUnitVectors, ()) {
  const double zenith = *in_range(-10, 190);
  const double azimuth = *in_range(-720, 720);
  const AnchorHeading heading{*in_range(-400, 400), *in_range(-30, 30)};
  RC_ASSERT(std::abs(norm(sun_direction_enu(zenith, azimuth)) - 1.0) < 1e-15);
  const SunInWorld w = sun_in_world(zenith, zenith, azimuth, heading);
  RC_ASSERT(std::abs(norm(w.towards_sun_world) - 1.0) < 1e-15);
  RC_ASSERT(w.azimuth_deg >= 0.0 && w.azimuth_deg < 360.0);
}

// --- poles --------------------------------------------------------------------------------------

RC_GTEST_PROP(SunProperties, AtThePolesElevationIsTheDeclination, ()) {
  const UtcInstant t = *any_time();
  const SpaResult north = spa_at(t, 90, *in_range(-180, 180));
  const SpaResult south = spa_at(t, -90, *in_range(-180, 180));
  for (const SpaResult* r : {&north, &south}) {
    RC_ASSERT(std::isfinite(r->azimuth) && std::isfinite(r->zenith));
    RC_ASSERT(r->azimuth >= 0.0 && r->azimuth < 360.0);
  }
  // At a pole the horizon is the celestial equator: e0 = ±δ′ exactly (cos 90° in double is 6e-17,
  // so 1e-9° is generous); δ′ differs from the geocentric δ by the parallax, < 8.8″ = 0.0025°.
  RC_ASSERT(std::abs(north.e0 - north.delta_prime) < 1e-9);
  RC_ASSERT(std::abs(south.e0 + south.delta_prime) < 1e-9);
  RC_ASSERT(std::abs(north.e0 - north.delta) < 0.0025);
  // PSA at the pole: finite too, and its zenith is 90° − δ up to its parallax and 0.01° accuracy.
  const PsaResult psa = psa_sun_position(t, 90, 0);
  RC_ASSERT(std::isfinite(psa.azimuth_deg));
  RC_ASSERT(std::abs(psa.zenith_deg - (90.0 - psa.declination_deg)) < 0.0025);
}

// --- date line ----------------------------------------------------------------------------------

RC_GTEST_PROP(SunProperties, LongitudesPlusAndMinus180AreTheSamePlace, ()) {
  const UtcInstant t = *any_time();
  const double lat = *in_range(-90, 90);
  const SpaResult east = spa_at(t, lat, 180), west = spa_at(t, lat, -180);
  RC_ASSERT(separation_deg(spa_enu(east), spa_enu(west)) < 1e-9);
  RC_ASSERT(std::abs(east.e - west.e) < 1e-9 || std::abs(east.e0 + 0.83337) < 1e-6);
  // 179.999 and −179.999 are 0.002° of longitude apart: the hour angle differs by 0.002°, which moves
  // the sun by at most 0.002° on the sky.
  const SpaResult e2 = spa_at(t, lat, 179.999), w2 = spa_at(t, lat, -179.999);
  RC_ASSERT(separation_deg(spa_enu(e2), spa_enu(w2)) < 0.0021);
  const PsaResult pe = psa_sun_position(t, lat, 180), pw = psa_sun_position(t, lat, -180);
  RC_ASSERT(separation_deg(sun_direction_enu(pe.zenith_deg, pe.azimuth_deg),
                           sun_direction_enu(pw.zenith_deg, pw.azimuth_deg)) < 1e-9);
}

// --- horizon ------------------------------------------------------------------------------------

RC_GTEST_PROP(SunProperties, RefractionNearTheHorizon, ()) {
  // Standard conditions (1010 mbar, 10 °C): Bennett-type refraction is 0.48° at e0 = 0 and 0.61°
  // at e0 = −0.8°, and nothing once the upper limb is below the refracted horizon (−0.83337°).
  const double e0 = *in_range(-0.8, 0.0);
  const double del_e = spa_refraction_deg(e0, 1010, 10, 0.5667);
  RC_ASSERT(del_e > 0.47 && del_e < 0.62);
  const double below = *in_range(-90, -0.8334);
  RC_ASSERT(spa_refraction_deg(below, 1010, 10, 0.5667) == 0.0);
}

TEST(SunProperties, RefractionAtSunriseThroughSpa) {
  // Find sunrise (geometric e0 = 0) at the NREL site by bisection, then check SPA adds ~0.5° there
  // (0.48° × 820/1010 × 283/284 = 0.39° at that site's 820 mbar, 11 °C) and none well below.
  SpaInput in;
  in.latitude_deg = 39.742476;
  in.longitude_deg = -105.1786;
  in.elevation_m = 1830.14;
  in.pressure_mbar = 1010;
  in.temperature_c = 10;
  in.delta_t_s = 67;
  double a = static_cast<double>(UtcInstant::parse("2003-10-17T11:00:00Z").unix_seconds());  // night
  double b = static_cast<double>(UtcInstant::parse("2003-10-17T16:00:00Z").unix_seconds());  // day
  for (int i = 0; i < 40; ++i) {
    const double m = 0.5 * (a + b);
    in.time = UtcInstant::from_unix_seconds(0).plus_seconds(m);
    (spa_sun_position(in).e0 < 0 ? a : b) = m;
  }
  in.time = UtcInstant::from_unix_seconds(0).plus_seconds(b);
  const SpaResult rise = spa_sun_position(in);
  EXPECT_NEAR(rise.e0, 0.0, 1e-4);
  EXPECT_NEAR(rise.del_e, 0.483, 0.005);
  in.time = in.time.plus_seconds(-1800);  // half an hour earlier: ~ −5°
  const SpaResult night = spa_sun_position(in);
  ASSERT_LT(night.e0, -0.84);
  EXPECT_EQ(night.del_e, 0.0);
  EXPECT_EQ(night.e, night.e0);
  const SunInWorld w = sun_in_world(night.zenith, night.zenith_geometric, night.azimuth, {});
  EXPECT_FALSE(w.above_horizon);
  const SunInWorld r = sun_in_world(rise.zenith, rise.zenith_geometric, rise.azimuth, {});
  EXPECT_TRUE(r.above_horizon);  // apparent elevation 0.48° > −0.26667°
  EXPECT_TRUE(r.centre_above_horizon());
}

TEST(SunProperties, AboveHorizonMeansTheUpperLimb) {
  // Apparent elevation of the centre −0.26° (upper limb still up): direct light, no shadow pass.
  const SunInWorld limb = sun_in_world(90.26, 90.7, 100, {});
  EXPECT_TRUE(limb.above_horizon);
  EXPECT_FALSE(limb.centre_above_horizon());
  const SunInWorld gone = sun_in_world(90.27, 90.9, 100, {});
  EXPECT_FALSE(gone.above_horizon);
}

// --- midnight UTC -------------------------------------------------------------------------------

RC_GTEST_PROP(SunProperties, ContinuousAcrossMidnightMonthYearAndLeapDay, ()) {
  const std::vector<std::string> midnights = {"2025-01-01T00:00:00Z", "2024-02-29T00:00:00Z", "2024-03-01T00:00:00Z",
                             "2025-03-01T00:00:00Z", "2000-03-01T00:00:00Z", "2026-07-01T00:00:00Z"};
  const UtcInstant midnight = UtcInstant::parse(*rc::gen::elementOf(midnights));
  const UtcInstant before = midnight.plus_seconds(-0.001);  // 23:59:59.999 the day before
  const double lat = *in_range(-90, 90), lon = *in_range(-180, 180);
  // JD (UT) steps by exactly 1 ms.
  RC_ASSERT(std::abs((midnight.julian_date().days_since_j2000() - before.julian_date().days_since_j2000()) * 86400.0 -
                     0.001) < 1e-7);
  // The sun moves by at most 15″/s = 0.0042°/s: 4.2e-6° in 1 ms.
  const SpaResult r0 = spa_at(before, lat, lon), r1 = spa_at(midnight, lat, lon);
  RC_ASSERT(separation_deg(spa_enu(r0), spa_enu(r1)) < 1e-5);
  const PsaResult p0 = psa_sun_position(before, lat, lon), p1 = psa_sun_position(midnight, lat, lon);
  RC_ASSERT(separation_deg(sun_direction_enu(p0.zenith_deg, p0.azimuth_deg),
                           sun_direction_enu(p1.zenith_deg, p1.azimuth_deg)) < 1e-5);
}

TEST(SunProperties, CalendarBoundaries) {
  EXPECT_EQ(UtcInstant::parse("2024-12-31T23:59:59.999Z").plus_seconds(0.001), UtcInstant::parse("2025-01-01T00:00:00Z"));
  EXPECT_EQ(UtcInstant::parse("2024-02-28T23:59:59.5Z").plus_seconds(0.5), UtcInstant::parse("2024-02-29T00:00:00Z"));
  EXPECT_EQ(UtcInstant::parse("2024-02-29T23:59:59.5Z").plus_seconds(0.5), UtcInstant::parse("2024-03-01T00:00:00Z"));
  EXPECT_EQ(UtcInstant::parse("2025-02-28T23:59:59.5Z").plus_seconds(0.5), UtcInstant::parse("2025-03-01T00:00:00Z"));
  EXPECT_THROW(UtcInstant::parse("2025-02-29T00:00:00Z"), std::invalid_argument);  // not a leap year
  EXPECT_THROW(UtcInstant::parse("1900-02-29T00:00:00Z"), std::invalid_argument);
  EXPECT_NO_THROW(UtcInstant::parse("2000-02-29T00:00:00Z"));
}

// --- heading and declination --------------------------------------------------------------------

RC_GTEST_PROP(SunProperties, HeadingRotatesAboutUpExactly, ()) {
  const double zenith = *in_range(0, 180), azimuth = *in_range(0, 360);
  const double heading = *in_range(-360, 360), declination = *in_range(-30, 30);
  const Vec3 enu = sun_direction_enu(zenith, azimuth);
  const Vec3 w = sun_in_world(zenith, zenith, azimuth, {heading, declination}).towards_sun_world;
  // The up component is untouched, bit for bit.
  RC_ASSERT(w[2] == enu[2]);
  // A rotation about +z by −psi: the world azimuth of the sun is its true azimuth minus psi.
  const double psi = heading + declination;
  const double horizontal = std::hypot(enu[0], enu[1]);
  RC_ASSERT(std::abs(std::hypot(w[0], w[1]) - horizontal) < 1e-15);
  if (horizontal > 1e-6) {
    const double world_azimuth = std::atan2(w[0], w[1]) * kRadToDeg;
    RC_ASSERT(std::abs(std::remainder(world_azimuth - (azimuth - psi), 360.0)) < 1e-9 / horizontal);
  }
  // Declination adds to the heading: (h, d) is the same as (h + d, 0).
  const Vec3 w2 = sun_in_world(zenith, zenith, azimuth, {psi, 0}).towards_sun_world;
  RC_ASSERT(separation_deg(w, w2) < 1e-12);
}

TEST(SunProperties, HeadingQuarterTurnsAreExact) {
  const Vec3 s = sun_direction_enu(50.111622, 194.340241);
  // +y of the anchor towards east (heading 90°): world x = south, world y = east.
  const Vec3 w90 = mat_mul(R_world_enu({90, 0}), s);
  EXPECT_EQ(w90[0], -s[1]);
  EXPECT_EQ(w90[1], s[0]);
  EXPECT_EQ(w90[2], s[2]);
  // Compass heading 100° with declination −10° is the true heading 90°.
  const Vec3 w90b = mat_mul(R_world_enu({100, -10}), s);
  EXPECT_EQ(w90b[0], w90[0]);
  EXPECT_EQ(w90b[1], w90[1]);
  const Vec3 w180 = mat_mul(R_world_enu({180, 0}), s);
  EXPECT_EQ(w180[0], -s[0]);
  EXPECT_EQ(w180[1], -s[1]);
  const Vec3 w0 = mat_mul(R_world_enu({0, 0}), s);
  EXPECT_EQ(w0, s);
}

// --- the worked example -------------------------------------------------------------------------

TEST(SunDirection, ReferenceExampleInEnu) {
  // calib_track_sun.md §4.5: Z = 50.111622°, A = 194.340241° gives s_ENU = (−0.190043, −0.743388,
  // 0.641294) (6 decimals: tolerance half a unit of the last digit).
  const Vec3 s = sun_direction_enu(50.111622, 194.340241);
  EXPECT_NEAR(s[0], -0.190043, 5e-7);
  EXPECT_NEAR(s[1], -0.743388, 5e-7);
  EXPECT_NEAR(s[2], 0.641294, 5e-7);
  // The sun-outdoor scene: azimuth 135°, elevation 40°, world north = +y: [0.5417, −0.5417, 0.6428].
  const SunInWorld w = sun_in_world(50, 50, 135, {});
  EXPECT_NEAR(w.towards_sun_world[0], 0.5417, 5e-5);
  EXPECT_NEAR(w.towards_sun_world[1], -0.5417, 5e-5);
  EXPECT_NEAR(w.towards_sun_world[2], 0.6428, 5e-5);
  EXPECT_DOUBLE_EQ(w.elevation_deg, 40.0);
}

// --- civil time ---------------------------------------------------------------------------------

TEST(CivilTime, ParsesIso8601Forms) {
  const UtcInstant t = UtcInstant::parse("2026-06-21T10:30:00Z");
  EXPECT_EQ(t.unix_seconds(), 1782037800);
  EXPECT_EQ(UtcInstant::parse("2026-06-21T12:30:00+02:00"), t);
  EXPECT_EQ(UtcInstant::parse("2026-06-21T12:30:00+0200"), t);
  EXPECT_EQ(UtcInstant::parse("2026-06-21T05:30:00-05"), t);
  EXPECT_EQ(UtcInstant::parse("2026-06-21 10:30:00"), t);  // no zone: UTC
  EXPECT_EQ(UtcInstant::parse("2026-06-21T10:30Z"), t);
  EXPECT_EQ(UtcInstant::parse("2026-06-21T10:30:00.123456789Z").subsecond_ns(), 123456789);
  EXPECT_EQ(UtcInstant::parse("2026-06-21T10:30:00.5Z").iso8601(), "2026-06-21T10:30:00.5Z");
  EXPECT_EQ(t.iso8601(), "2026-06-21T10:30:00Z");
  EXPECT_EQ(UtcInstant::parse("1969-12-31T23:59:59.75Z").unix_ns(), -250'000'000);
}

TEST(CivilTime, BadTextNamesTheTextAndWhatWasExpected) {
  for (const char* bad : {"", "2026-6-21T10:30:00Z", "2026-06-21", "2026-06-21T25:00:00Z", "2026-13-01T00:00:00Z",
                          "2026-06-21T10:30:00Q", "2026-06-21T10:30:60Z", "2026-06-21T10:30:00.Z", "yesterday",
                          "2026-06-21T10:30:00+25:00"}) {
    try {
      UtcInstant::parse(bad);
      ADD_FAILURE() << "no error for '" << bad << "'";
    } catch (const std::invalid_argument& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(std::string("'") + bad + "'"), std::string::npos) << what;
      EXPECT_TRUE(what.find("expected") != std::string::npos || what.find("out of range") != std::string::npos)
          << what;
    }
  }
}

RC_GTEST_PROP(CivilTime, UnixNanosecondsRoundTrip, (int64_t ns)) {
  const UtcInstant t = UtcInstant::from_unix_ns(ns);
  RC_ASSERT(t.unix_ns() == ns);
  RC_ASSERT(UtcInstant::parse(t.iso8601()) == t);
  const CivilDateTime c = t.civil();
  RC_ASSERT(UtcInstant::from_civil(c) == t);
}

TEST(CivilTime, JulianDayKeepsNanoseconds) {
  // J2000.0 = 2000-01-01T12:00:00 (here UT) = JD 2451545.0.
  const JulianDate j = UtcInstant::parse("2000-01-01T12:00:00Z").julian_date();
  EXPECT_EQ(j.day, 2451545.0);
  EXPECT_EQ(j.fraction, 0.0);
  EXPECT_EQ(UtcInstant::parse("1970-01-01T00:00:00Z").julian_date().value(), 2440587.5);
  // 1 ns after noon in 2026: the fraction resolves it (a single double JD would only resolve ~40 µs).
  const JulianDate k = UtcInstant::parse("2026-06-21T12:00:00.000000001Z").julian_date();
  EXPECT_NEAR(k.fraction * 86400e9, 1.0, 1e-3);
  // ΔT offsets move the JDE by exactly offset/86400.
  const JulianDate l = UtcInstant::parse("2026-06-21T23:59:30Z").julian_date(69.184);
  EXPECT_NEAR((l.days_since_j2000() - UtcInstant::parse("2026-06-21T23:59:30Z").julian_date().days_since_j2000()) *
                  86400.0,
              69.184, 1e-6);
}

}  // namespace
}  // namespace arpipe
