// Benchmark: run time per call of the sun-position algorithms (NREL SPA, seed 001's PSA) and of
// the direction into the anchor frame. `arpipe bench sun [--calls N] [--repeats R]`
// Prints ns per call, the median over R repeats of N calls each, with PSA's error against SPA.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "apps/cli/command_line.h"
#include "bench/benchmarks.h"
#include "core/sun/civil_time.h"
#include "core/sun/sun_direction.h"
#include "core/sun/sun_position_psa.h"
#include "core/sun/sun_position_spa.h"

namespace arpipe {
namespace {

struct Sample {
  UtcInstant time;
  double lat, lon;
};

template <class F>
double median_ns_per_call(int calls, int repeats, F&& f) {
  std::vector<double> ns;
  for (int r = 0; r < repeats; ++r) {
    const auto start = std::chrono::steady_clock::now();
    for (int i = 0; i < calls; ++i) f(i);
    const auto stop = std::chrono::steady_clock::now();
    ns.push_back(std::chrono::duration<double, std::nano>(stop - start).count() / calls);
  }
  std::nth_element(ns.begin(), ns.begin() + ns.size() / 2, ns.end());
  return ns[ns.size() / 2];
}

int run_sun_benchmark(int calls, int repeats) {
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> lat(-80, 80), lon(-180, 180);
  std::uniform_int_distribution<int64_t> secs(946684800, 2556143999);  // 2000..2050
  std::vector<Sample> samples(1024);
  for (Sample& s : samples) s = {UtcInstant::from_unix_seconds(secs(rng)), lat(rng), lon(rng)};

  volatile double sink = 0;
  const double spa_ns = median_ns_per_call(calls, repeats, [&](int i) {
    const Sample& s = samples[static_cast<size_t>(i) & 1023];
    SpaInput in;
    in.time = s.time;
    in.latitude_deg = s.lat;
    in.longitude_deg = s.lon;
    sink = sink + spa_sun_position(in).zenith;
  });
  const double psa_ns = median_ns_per_call(calls, repeats, [&](int i) {
    const Sample& s = samples[static_cast<size_t>(i) & 1023];
    sink = sink + psa_sun_position(s.time, s.lat, s.lon).zenith_deg;
  });
  const double dir_ns = median_ns_per_call(calls, repeats, [&](int i) {
    const Sample& s = samples[static_cast<size_t>(i) & 1023];
    sink = sink + sun_in_world(s.lat + 90, s.lat + 90, s.lon, {30, 2}).towards_sun_world[0];
  });

  double max_err = 0;
  for (const Sample& s : samples) {
    SpaInput in;
    in.time = s.time;
    in.latitude_deg = s.lat;
    in.longitude_deg = s.lon;
    const SpaResult r = spa_sun_position(in);
    if (r.e0 <= 0) continue;
    const PsaResult p = psa_sun_position(s.time, s.lat, s.lon);
    const Vec3 a = sun_direction_enu(p.zenith_deg, p.azimuth_deg), b = sun_direction_enu(r.zenith_geometric, r.azimuth);
    max_err = std::max(max_err, std::atan2(norm(cross(a, b)), dot(a, b)) * 180.0 / M_PI);
  }

  fmt::print("| algorithm | ns per call (median of {} x {}) | max angle to SPA, 2000-2050, sun up |\n", repeats, calls);
  fmt::print("|---|---|---|\n");
  fmt::print("| NREL SPA (topocentric, refraction) | {:.0f} | reference (+-0.0003 deg) |\n", spa_ns);
  fmt::print("| PSA (seed 001) | {:.0f} | {:.4f} deg |\n", psa_ns, max_err);
  fmt::print("| sun_in_world (ENU -> anchor) | {:.0f} | - |\n", dir_ns);
  return sink == 12345.678 ? 1 : 0;
}

}  // namespace

void add_sun_benchmark(CLI::App& bench) {
  CLI::App* command = bench.add_subcommand(
      "sun", "run time per call of the sun-position algorithms (NREL SPA, PSA), PSA's error against SPA");
  struct Options {
    int calls = 20000, repeats = 15;
  };
  auto options = std::make_shared<Options>();
  command->add_option("--calls", options->calls, "calls per timed repeat")->check(CLI::PositiveNumber);
  command->add_option("--repeats", options->repeats, "timed repeats (the median is printed)")->type_name("R")->check(CLI::PositiveNumber);
  cli::on_run(command, [options] { return run_sun_benchmark(options->calls, options->repeats); }, cli::Failure{});
}

}  // namespace arpipe
