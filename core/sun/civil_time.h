// A UTC instant (proleptic Gregorian calendar, no leap seconds, like Unix time): ISO 8601 parsing,
// Unix nanoseconds, calendar fields and the Julian Day the sun-position algorithms start from.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace arpipe {

// Calendar fields of an instant in UTC. second is 0..59: Unix time cannot name a leap second.
struct CivilDateTime {
  int year = 2000;  // astronomical numbering (0 = 1 BC), proleptic Gregorian
  int month = 1;    // 1..12
  int day = 1;      // 1..31
  int hour = 0;
  int minute = 0;
  int second = 0;
  int64_t nanosecond = 0;  // 0..999'999'999
};

// A Julian Day split so that nothing is lost at nanosecond resolution: day is an integer (the JD
// at the noon that starts this Julian day), fraction is in [0, 1).
struct JulianDate {
  double day = 2451545.0;
  double fraction = 0.0;
  double value() const { return day + fraction; }
  double days_since_j2000() const { return (day - 2451545.0) + fraction; }  // exact integer part
};

class UtcInstant {
 public:
  UtcInstant() = default;
  static UtcInstant from_unix_ns(int64_t unix_ns);
  // nanosecond may be any value; it is carried into the seconds.
  static UtcInstant from_unix_seconds(int64_t seconds, int64_t nanosecond = 0);
  // Throws std::invalid_argument naming the field and its range if a field is out of range.
  static UtcInstant from_civil(const CivilDateTime& civil);
  // "2026-06-21T10:30:00Z", "2026-06-21T12:30:00.25+02:00", "2026-06-21 10:30:00" (no zone = UTC),
  // seconds optional, 'T' or a space between date and time, zone Z, +HH:MM, +HHMM or +HH.
  // Throws std::invalid_argument naming the text and what was expected.
  static UtcInstant parse(std::string_view iso8601);

  // Throws std::out_of_range outside 1677-09-21 .. 2262-04-11 (int64 nanoseconds).
  int64_t unix_ns() const;
  int64_t unix_seconds() const { return seconds_; }
  int64_t subsecond_ns() const { return nanos_; }  // 0..999'999'999
  CivilDateTime civil() const;
  std::string iso8601() const;  // "2026-06-21T10:30:00Z", fractional digits only when needed
  double decimal_year() const;  // 2026.0 at 2026-01-01T00:00Z, linear in time within the year

  UtcInstant plus_seconds(double seconds) const;
  // The Julian Day of this instant shifted by offset_s seconds: offset ΔUT1 gives JD(UT1),
  // ΔUT1 + ΔT gives JDE (TT).
  JulianDate julian_date(double offset_s = 0.0) const;

  friend bool operator==(const UtcInstant&, const UtcInstant&) = default;

 private:
  int64_t seconds_ = 0;  // since 1970-01-01T00:00:00Z
  int64_t nanos_ = 0;    // 0..999'999'999
};

}  // namespace arpipe
