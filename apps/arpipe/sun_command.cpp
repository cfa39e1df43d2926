// arpipe sun: where the sun is for a place and a UTC time (SPA and/or PSA), as azimuth, zenith,
// elevation, an East-North-Up vector and, given the anchor's heading, a vector in the anchor frame.
#include <fmt/format.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include "apps/arpipe/commands.h"
#include "apps/cli/command_line.h"
#include "core/sun/civil_time.h"
#include "core/sun/delta_t.h"
#include "core/sun/sun_direction.h"
#include "core/sun/sun_position_psa.h"
#include "core/sun/sun_position_spa.h"

namespace arpipe {

namespace {

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

struct SunOptions {
  std::string time, algorithm = "spa";
  SpaInput in;  // all but the time
  std::optional<double> delta_t_s, heading_deg;
  double declination_deg = 0;
};

int run_sun(SunOptions options) {
  SpaInput& in = options.in;
  try {
    in.time = UtcInstant::parse(options.time);
  } catch (const std::invalid_argument& e) {
    cli::usage_error(fmt::format("--time: {}", e.what()));
  }
  const bool delta_t_given = options.delta_t_s.has_value();
  in.delta_t_s = delta_t_given ? *options.delta_t_s : delta_t_estimate_s(in.time.decimal_year());
  std::optional<AnchorHeading> heading;
  if (options.heading_deg) heading = AnchorHeading{*options.heading_deg, options.declination_deg};
  const std::string& algorithm = options.algorithm;

  // The config boundary: SPA's checks name the value and its range (latitude 95 -> exit 2).
  try {
    validate_spa_input(in);
  } catch (const std::invalid_argument& e) {
    cli::usage_error(e.what());
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

}  // namespace

void add_sun_command(CLI::App& arpipe) {
  CLI::App* command = arpipe.add_subcommand(
      "sun", "the sun's azimuth, elevation and direction (ENU, anchor frame) for a place and time (NREL SPA and/or PSA)");
  auto options = std::make_shared<SunOptions>();
  SpaInput& in = options->in;
  command->add_option("--lat", in.latitude_deg, "latitude, north positive")->type_name("DEG")
      ->check(cli::finite_number())->required();
  command->add_option("--lon", in.longitude_deg, "longitude, east positive")->type_name("DEG")
      ->check(cli::finite_number())->required();
  command->add_option("--time", options->time, "ISO 8601: 2026-06-21T10:30:00Z, ...+02:00; no zone = UTC")
      ->type_name("ISO8601")
      ->required();
  command->add_option("--alt", in.elevation_m, "altitude in metres")->type_name("M")
      ->check(cli::finite_number());
  command->add_option_function<double>("--delta-t", [options](const double& s) { options->delta_t_s = s; },
                                       "TT - UT in seconds")
      ->type_name("S")
      ->check(cli::finite_number())
      ->default_str("the Espenak-Meeus estimate");
  command->add_option("--pressure", in.pressure_mbar, "air pressure, for the refraction")->type_name("MBAR")
      ->check(cli::finite_number());
  command->add_option("--temperature", in.temperature_c, "air temperature, for the refraction")->type_name("C")
      ->check(cli::finite_number());
  CLI::Option* heading =
      command->add_option_function<double>("--heading", [options](const double& deg) { options->heading_deg = deg; },
                                           "bearing of the anchor's +y axis (the tag's top edge) from true north, "
                                           "clockwise")
          ->type_name("DEG")
      ->check(cli::finite_number());
  command->add_option("--declination", options->declination_deg,
                      "degrees east, added when the heading was read off a compass")
      ->type_name("DEG")
      ->check(cli::finite_number())
      ->needs(heading);
  command->add_option("--algorithm", options->algorithm, "spa (NREL SPA), psa (seed 001's PSA) or both")
      ->check(CLI::IsMember({"spa", "psa", "both"}));
  cli::on_run(command, [options] { return run_sun(*options); });
}

}  // namespace arpipe
