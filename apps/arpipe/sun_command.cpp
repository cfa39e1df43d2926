// arpipe sun: where the sun is for a place and a UTC time (SPA and/or PSA), as azimuth, zenith,
// elevation, an East-North-Up vector and, given the anchor's heading, a vector in the anchor frame.
#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <cstdio>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>

#include "apps/arpipe/commands.h"
#include "apps/arpipe/parse_number.h"
#include "core/sun/civil_time.h"
#include "core/sun/delta_t.h"
#include "core/sun/sun_direction.h"
#include "core/sun/sun_position_psa.h"
#include "core/sun/sun_position_spa.h"

namespace arpipe {

namespace {

constexpr const char* kUsage =
    "usage: arpipe sun --lat DEG --lon DEG --time ISO8601 [--alt M] [--delta-t S] [--pressure MBAR]\n"
    "                  [--temperature C] [--heading DEG] [--declination DEG] [--algorithm spa|psa|both]\n"
    "  Where the sun is, seen from latitude/longitude (degrees, north and east positive) at altitude M\n"
    "  (metres, default 0), at the time given in ISO 8601 (2026-06-21T10:30:00Z, ...+02:00; no zone = UTC).\n"
    "  --delta-t: TT - UT in seconds (default: Espenak-Meeus estimate); --pressure (default 1013.25 mbar)\n"
    "  and --temperature (default 15 C) set the refraction. --heading: bearing of the anchor's +y axis\n"
    "  (the tag's top edge) from true north, clockwise; --declination (degrees east) is added when the\n"
    "  heading was read off a compass. --algorithm: spa (default, NREL SPA), psa (seed 001's PSA) or both.\n";

int usage_error(const std::string& message) {
  fmt::print(stderr, "arpipe sun: {}\n{}", message, kUsage);
  return 2;
}

void print_direction(const char* label, const Vec3& v) {
  fmt::print("  {:<28} [{:+.6f}, {:+.6f}, {:+.6f}]\n", label, v[0], v[1], v[2]);
}

void print_sun(const char* name, double azimuth, double zenith_apparent, double zenith_geometric,
               const std::optional<AnchorHeading>& heading, bool refracted) {
  const SunInWorld w = sun_in_world(zenith_apparent, zenith_geometric, azimuth, heading.value_or(AnchorHeading{}));
  fmt::print("{}:\n", name);
  fmt::print("  {:<28} {:.6f} deg (east of true north)\n", "azimuth", w.azimuth_deg);
  if (refracted) {
    fmt::print("  {:<28} {:.6f} deg\n", "zenith (apparent)", zenith_apparent);
    fmt::print("  {:<28} {:.6f} deg\n", "elevation (refracted)", w.elevation_deg);
  } else {
    fmt::print("  {:<28} {:.6f} deg\n", "zenith (no refraction)", zenith_apparent);
    fmt::print("  {:<28} (not modelled)\n", "elevation (refracted)");
  }
  fmt::print("  {:<28} {:.6f} deg\n", "elevation (no refraction)", w.elevation_geometric_deg);
  print_direction("towards the sun, ENU", sun_direction_enu(zenith_apparent, azimuth));
  if (heading)
    print_direction("towards the sun, anchor", w.towards_sun_world);
  if (!w.above_horizon)
    fmt::print("  the sun is below the horizon: no direct light\n");
  else if (!w.centre_above_horizon())
    fmt::print("  only the upper limb is above the horizon: direct light, no shadows cast\n");
}

}  // namespace

int run_sun(const Args& args) {
  std::map<std::string, std::string> values;
  static const char* const kOptions[] = {"--lat",      "--lon",     "--alt",         "--time",
                                         "--delta-t",  "--pressure", "--temperature", "--heading",
                                         "--declination", "--algorithm"};
  for (size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "--help" || args[i] == "-h") {
      std::fputs(kUsage, stdout);
      return 0;
    }
    bool known = false;
    for (const char* o : kOptions) known = known || args[i] == o;
    if (!known) return usage_error(fmt::format("unexpected argument '{}'", args[i]));
    if (i + 1 >= args.size()) return usage_error(fmt::format("{} needs a value", args[i]));
    if (values.count(args[i]) != 0) return usage_error(fmt::format("{} given twice", args[i]));
    values[args[i]] = args[i + 1];
    ++i;
  }
  for (const char* required : {"--lat", "--lon", "--time"})
    if (values.count(required) == 0) return usage_error(fmt::format("{} is required", required));

  std::map<std::string, double> numbers;
  for (const auto& [key, text] : values) {
    if (key == "--time" || key == "--algorithm") continue;
    const std::optional<double> v = parse_number(text);
    if (!v) return usage_error(fmt::format("bad value '{}' for {}: expected a number", text, key));
    numbers[key] = *v;
  }
  const std::string algorithm = values.count("--algorithm") ? values["--algorithm"] : "spa";
  if (algorithm != "spa" && algorithm != "psa" && algorithm != "both")
    return usage_error(fmt::format("bad value '{}' for --algorithm: expected spa, psa or both", algorithm));

  SpaInput in;
  try {
    in.time = UtcInstant::parse(values["--time"]);
  } catch (const std::invalid_argument& e) {
    return usage_error(fmt::format("--time: {}", e.what()));
  }
  in.latitude_deg = numbers["--lat"];
  in.longitude_deg = numbers["--lon"];
  if (numbers.count("--alt")) in.elevation_m = numbers["--alt"];
  if (numbers.count("--pressure")) in.pressure_mbar = numbers["--pressure"];
  if (numbers.count("--temperature")) in.temperature_c = numbers["--temperature"];
  const bool delta_t_given = numbers.count("--delta-t") != 0;
  in.delta_t_s = delta_t_given ? numbers["--delta-t"] : delta_t_estimate_s(in.time.decimal_year());
  std::optional<AnchorHeading> heading;
  if (numbers.count("--heading"))
    heading = AnchorHeading{numbers["--heading"], numbers.count("--declination") ? numbers["--declination"] : 0.0};
  else if (numbers.count("--declination"))
    return usage_error("--declination needs --heading (the compass reading it corrects)");

  // The config boundary: SPA's checks name the value and its range (latitude 95 -> exit 2).
  try {
    validate_spa_input(in);
  } catch (const std::invalid_argument& e) {
    return usage_error(e.what());
  }

  fmt::print("time (UTC)                     {}\n", in.time.iso8601());
  fmt::print("place                          latitude {:.6f}, longitude {:.6f} deg, altitude {:g} m\n",
             in.latitude_deg, in.longitude_deg, in.elevation_m);
  fmt::print("delta T (TT - UT)              {:.3f} s ({})\n", in.delta_t_s,
             delta_t_given ? "given" : "Espenak-Meeus estimate");
  if (heading)
    fmt::print("anchor +y heading              {:.6f} deg true ({:g} + declination {:g})\n", heading->true_heading_deg(),
               heading->heading_deg, heading->declination_deg);
  if (algorithm == "spa" || algorithm == "both") {
    const SpaResult r = spa_sun_position(in);
    fmt::print("pressure, temperature          {:g} mbar, {:g} C\n", in.pressure_mbar, in.temperature_c);
    print_sun("SPA (NREL, +-0.0003 deg)", r.azimuth, r.zenith, r.zenith_geometric, heading, true);
  }
  if (algorithm == "psa" || algorithm == "both") {
    const PsaResult p = psa_sun_position(in.time, in.latitude_deg, in.longitude_deg);
    // PSA has no refraction: its apparent and geometric zenith are the same.
    print_sun("PSA (seed 001; no refraction, ~0.01 deg)", p.azimuth_deg, p.zenith_deg, p.zenith_deg, heading, false);
  }
  return 0;
}

}  // namespace arpipe
