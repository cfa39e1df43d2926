// A UTC instant: ISO 8601 parsing, calendar arithmetic (Howard Hinnant's days-from-civil
// algorithms, exact for the proleptic Gregorian calendar) and the split Julian Day.
#include "core/sun/civil_time.h"

#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <stdexcept>

namespace arpipe {

namespace {

constexpr int64_t kNsPerS = 1'000'000'000;
constexpr int64_t kSecondsPerDay = 86'400;
constexpr double kJdUnixEpoch = 2440587.5;  // JD of 1970-01-01T00:00Z

int64_t floor_div(int64_t a, int64_t b) { return a / b - ((a % b != 0) && ((a < 0) != (b < 0))); }

int64_t days_from_civil(int64_t y, int m, int d) {
  y -= m <= 2;
  const int64_t era = floor_div(y, 400);
  const int64_t yoe = y - era * 400;
  const int64_t doy = (153 * (m + (m > 2 ? -3 : 9)) + 2) / 5 + d - 1;
  const int64_t doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + doe - 719468;
}

void civil_from_days(int64_t z, int& y, int& m, int& d) {
  z += 719468;
  const int64_t era = floor_div(z, 146097);
  const int64_t doe = z - era * 146097;
  const int64_t yoe = (doe - doe / 1460 + doe / 36524 - doe / 146096) / 365;
  const int64_t doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
  const int64_t mp = (5 * doy + 2) / 153;
  d = static_cast<int>(doy - (153 * mp + 2) / 5 + 1);
  m = static_cast<int>(mp < 10 ? mp + 3 : mp - 9);
  y = static_cast<int>(yoe + era * 400 + (m <= 2));
}

bool is_leap(int y) { return (y % 4 == 0 && y % 100 != 0) || y % 400 == 0; }
int days_in_month(int y, int m) {
  static constexpr int kDays[] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  return m == 2 && is_leap(y) ? 29 : kDays[m - 1];
}

void check_field(const char* name, int64_t value, int64_t lo, int64_t hi) {
  if (value < lo || value > hi)
    throw std::invalid_argument(fmt::format("{} {} is out of range: expected {}..{}", name, value, lo, hi));
}

// A cursor over the text with error messages that quote the whole text.
struct Parser {
  std::string_view text;
  size_t pos = 0;

  [[noreturn]] void fail(std::string_view expected) const {
    throw std::invalid_argument(fmt::format(
        "bad time '{}': expected {} at character {} (ISO 8601, e.g. 2026-06-21T10:30:00Z, "
        "2026-06-21T12:30:00.5+02:00 or 2026-06-21 10:30:00 for UTC)",
        text, expected, pos + 1));
  }
  bool at_end() const { return pos >= text.size(); }
  char peek() const { return at_end() ? '\0' : text[pos]; }
  int digits(int count, std::string_view what) {
    int v = 0;
    for (int i = 0; i < count; ++i) {
      if (at_end() || text[pos] < '0' || text[pos] > '9') fail(what);
      v = v * 10 + (text[pos++] - '0');
    }
    return v;
  }
  void expect(char c, std::string_view what) {
    if (peek() != c) fail(what);
    ++pos;
  }
};

}  // namespace

UtcInstant UtcInstant::from_unix_seconds(int64_t seconds, int64_t nanosecond) {
  UtcInstant t;
  t.seconds_ = seconds + floor_div(nanosecond, kNsPerS);
  t.nanos_ = nanosecond - floor_div(nanosecond, kNsPerS) * kNsPerS;
  return t;
}

UtcInstant UtcInstant::from_unix_ns(int64_t unix_ns) { return from_unix_seconds(0, unix_ns); }

UtcInstant UtcInstant::from_civil(const CivilDateTime& c) {
  check_field("year", c.year, -9999, 99999);
  check_field("month", c.month, 1, 12);
  check_field("day", c.day, 1, days_in_month(c.year, c.month));
  check_field("hour", c.hour, 0, 23);
  check_field("minute", c.minute, 0, 59);
  check_field("second", c.second, 0, 59);
  check_field("nanosecond", c.nanosecond, 0, kNsPerS - 1);
  const int64_t days = days_from_civil(c.year, c.month, c.day);
  return from_unix_seconds(days * kSecondsPerDay + c.hour * 3600 + c.minute * 60 + c.second, c.nanosecond);
}

UtcInstant UtcInstant::parse(std::string_view text) {
  Parser p{text};
  CivilDateTime c;
  const bool negative = p.peek() == '-';
  if (negative || p.peek() == '+') ++p.pos;
  c.year = p.digits(4, "a 4-digit year");
  if (negative) c.year = -c.year;
  p.expect('-', "'-' after the year");
  c.month = p.digits(2, "a 2-digit month");
  p.expect('-', "'-' after the month");
  c.day = p.digits(2, "a 2-digit day");
  if (p.peek() != 'T' && p.peek() != 't' && p.peek() != ' ') p.fail("'T' or a space between date and time");
  ++p.pos;
  c.hour = p.digits(2, "a 2-digit hour");
  p.expect(':', "':' after the hour");
  c.minute = p.digits(2, "a 2-digit minute");
  if (p.peek() == ':') {
    ++p.pos;
    c.second = p.digits(2, "2-digit seconds");
    if (p.peek() == '.' || p.peek() == ',') {
      ++p.pos;
      int count = 0;
      int64_t scale = kNsPerS;
      while (!p.at_end() && p.peek() >= '0' && p.peek() <= '9') {
        if (count < 9) {
          scale /= 10;
          c.nanosecond += (p.peek() - '0') * scale;
        }
        ++count;
        ++p.pos;
      }
      if (count == 0) p.fail("digits after the decimal point");
      // Digits past nanoseconds are dropped (truncated), as the instant holds whole nanoseconds.
    }
  }
  int64_t zone_s = 0;
  if (p.peek() == 'Z' || p.peek() == 'z') {
    ++p.pos;
  } else if (p.peek() == '+' || p.peek() == '-') {
    const int sign = p.peek() == '-' ? -1 : 1;
    ++p.pos;
    const int zh = p.digits(2, "a 2-digit zone hour");
    int zm = 0;
    if (p.peek() == ':') {
      ++p.pos;
      zm = p.digits(2, "a 2-digit zone minute");
    } else if (!p.at_end()) {
      zm = p.digits(2, "a 2-digit zone minute");
    }
    if (zh > 18 || zm > 59) p.fail("a zone offset within +-18:00");
    zone_s = sign * (zh * 3600 + zm * 60);
  }
  if (!p.at_end()) p.fail("the end of the text (or a zone: Z, +HH:MM)");
  try {
    const UtcInstant local = from_civil(c);
    return from_unix_seconds(local.seconds_ - zone_s, local.nanos_);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(fmt::format("bad time '{}': {}", text, e.what()));
  }
}

int64_t UtcInstant::unix_ns() const {
  constexpr int64_t kMax = std::numeric_limits<int64_t>::max();
  constexpr int64_t kMin = std::numeric_limits<int64_t>::min();
  if (seconds_ > (kMax - nanos_) / kNsPerS || seconds_ < kMin / kNsPerS + 1)
    throw std::out_of_range(fmt::format("time {} does not fit in int64 Unix nanoseconds (1677..2262)", iso8601()));
  return seconds_ * kNsPerS + nanos_;
}

CivilDateTime UtcInstant::civil() const {
  CivilDateTime c;
  const int64_t days = floor_div(seconds_, kSecondsPerDay);
  const int64_t sod = seconds_ - days * kSecondsPerDay;
  civil_from_days(days, c.year, c.month, c.day);
  c.hour = static_cast<int>(sod / 3600);
  c.minute = static_cast<int>(sod / 60 % 60);
  c.second = static_cast<int>(sod % 60);
  c.nanosecond = nanos_;
  return c;
}

std::string UtcInstant::iso8601() const {
  const CivilDateTime c = civil();
  std::string s = fmt::format("{:04d}-{:02d}-{:02d}T{:02d}:{:02d}:{:02d}", c.year, c.month, c.day, c.hour, c.minute,
                              c.second);
  if (c.nanosecond != 0) {
    std::string frac = fmt::format("{:09d}", c.nanosecond);
    while (frac.back() == '0') frac.pop_back();
    s += "." + frac;
  }
  return s + "Z";
}

double UtcInstant::decimal_year() const {
  const int y = civil().year;
  const int64_t start = days_from_civil(y, 1, 1) * kSecondsPerDay;
  const int64_t end = days_from_civil(y + 1, 1, 1) * kSecondsPerDay;
  return y + (static_cast<double>(seconds_ - start) + 1e-9 * static_cast<double>(nanos_)) /
                 static_cast<double>(end - start);
}

UtcInstant UtcInstant::plus_seconds(double seconds) const {
  const double whole = std::floor(seconds);
  return from_unix_seconds(seconds_ + static_cast<int64_t>(whole),
                           nanos_ + static_cast<int64_t>(std::llround((seconds - whole) * 1e9)));
}

JulianDate UtcInstant::julian_date(double offset_s) const {
  // Count from noon (the Julian day starts at noon) in integer seconds, so the fraction keeps its
  // full relative precision: 1 ns after noon is 1.16e-14, not 1 + 1.16e-14 − 1.
  const double whole = std::floor(offset_s);
  const int64_t s_noon = seconds_ + static_cast<int64_t>(whole) - kSecondsPerDay / 2;
  const int64_t days = floor_div(s_noon, kSecondsPerDay);
  const double sec = static_cast<double>(s_noon - days * kSecondsPerDay) + 1e-9 * static_cast<double>(nanos_) +
                     (offset_s - whole);  // 0 .. < 86402
  double day = (kJdUnixEpoch + 0.5) + static_cast<double>(days);  // 2440588 = JD at 1970-01-01T12:00
  double fraction = sec / 86400.0;
  if (fraction >= 1.0) {
    day += 1.0;
    fraction = (sec - 86400.0) / 86400.0;
  }
  return {day, fraction};
}

}  // namespace arpipe
