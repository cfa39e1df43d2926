// Benchmark: the rigid-body physics (core/physics) against its substep rate: run time per 30 fps
// frame of a busy scene against the error of a ball's bounce and landing against the closed forms.
// `arpipe bench physics [--seconds S]`. The rows come from one run: compare them with each other.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <vector>

#include "apps/cli/command_line.h"
#include "bench/benchmarks.h"
#include "core/physics/rigid_world.h"

namespace arpipe {
namespace {

constexpr double kStandardGravity = 9.80665;
constexpr int64_t kPhysicsBenchStartNs = 1'000'000'000'000;
constexpr int64_t kFrameNs = 33'333'333;

SE3 physics_bench_at(const Vec3& t) { return SE3(identity3(), t); }

RigidBodySpec physics_bench_ball(const Vec3& centre, double radius, double restitution, const Vec3& velocity = {0, 0, 0}) {
  RigidBodySpec b;
  b.name = "ball";
  b.mass_kg = 0.2;
  b.shape = SphereShape{radius};
  b.T_world_body = physics_bench_at(centre);
  b.restitution = restitution;
  b.linear_velocity_mps = velocity;
  return b;
}

struct DropError {
  double bounce_relative = 0;  // |bounce height / (e^2 h) - 1|, worst
  double landing_s = 0;        // |landing time - sqrt(2h/g)|, worst
};

// A ball dropped from h onto the ground: its first bounce height against e^2 h and its landing time
// against sqrt(2h/g), worst over three heights and three restitutions.
DropError drop_errors(int substep_hz) {
  RigidWorldSettings settings;
  settings.substep_hz = substep_hz;
  DropError worst;
  constexpr double r = 0.05;
  for (double h : {0.25, 1.0, 3.0})
    for (double e : {0.3, 0.6, 0.9}) {
      RigidWorld world(settings);
      world.add_collider(ColliderSpec{});  // the ground plane
      const size_t id = world.add_body(physics_bench_ball({0, 0, h + r}, r, e));
      world.start(kPhysicsBenchStartNs);
      // The landing is the substep where the fall turns into the rebound (contacts are solved a
      // little before the surfaces meet, by up to a substep's travel, so "bottom <= 0" may never hold).
      double landing = -1, peak = 0;
      while (world.newest_ns() < kPhysicsBenchStartNs + 2'500'000'000) {
        world.advance_to(world.newest_ns() + 1);
        const BodySample s = world.sample_at(id, world.newest_ns());
        const double bottom = s.T_world_body.translation()[2] - r, t = double(world.newest_ns() - kPhysicsBenchStartNs) * 1e-9;
        if (landing < 0) {
          if (s.linear_velocity_mps[2] > 0) landing = t;
          continue;
        }
        if (s.linear_velocity_mps[2] < 0) break;
        peak = std::max(peak, bottom);
      }
      worst.bounce_relative = std::max(worst.bounce_relative, std::abs(peak / (e * e * h) - 1));
      worst.landing_s = std::max(worst.landing_s, std::abs(landing - std::sqrt(2 * h / kStandardGravity)));
    }
  return worst;
}

// A busy scene: a stack of five boxes, a ball thrown at it off a table-sized box, and a second ball
// bouncing on the ground; advanced in 30 fps frames, the renderer's nine exposure instants sampled
// per frame. Returns the milliseconds per frame.
double ms_per_frame(int substep_hz, double seconds) {
  RigidWorldSettings settings;
  settings.substep_hz = substep_hz;
  RigidWorld world(settings);
  world.add_collider(ColliderSpec{});
  ColliderSpec table;
  table.shape = BoxShape{{0.4, 0.3, 0.35}};
  table.T_world_collider = physics_bench_at({1.0, 0, 0.35});
  world.add_collider(table);
  std::vector<size_t> bodies;
  for (int i = 0; i < 5; ++i) {
    RigidBodySpec box;
    box.name = "box";
    box.mass_kg = 0.5;
    box.shape = BoxShape{{0.05, 0.05, 0.05}};
    box.T_world_body = SE3::from_rt({0, 0, 0.05 * i}, {0, 0, 0.05 + 0.1 * i});
    bodies.push_back(world.add_body(box));
  }
  bodies.push_back(world.add_body(physics_bench_ball({1.2, 0, 0.9}, 0.04, 0.6, {-2.0, 0, 1.0})));
  bodies.push_back(world.add_body(physics_bench_ball({-0.5, 0.3, 1.0}, 0.05, 0.8)));
  world.start(kPhysicsBenchStartNs);
  const int frames = std::max(1, int(seconds * 30));
  double sink = 0;
  const auto start = std::chrono::steady_clock::now();
  for (int f = 1; f <= frames; ++f) {
    const int64_t end = kPhysicsBenchStartNs + f * kFrameNs;
    world.advance_to(end);
    for (const size_t body : bodies)
      for (int k = 0; k < 9; ++k) sink += world.pose_at(body, end - kFrameNs + k * kFrameNs / 8).translation()[2];
  }
  const double total = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return std::isfinite(sink) ? total / frames : -1;
}

int run_physics_benchmark(double seconds) {
  fmt::print("| substeps per second | ms per 30 fps frame (5-box stack, 2 balls, a table; {:.0f} s) | worst bounce height error "
             "(e^2 h; 3 heights x 3 restitutions) | worst landing time error (sqrt(2h/g)) |\n",
             seconds);
  fmt::print("|---:|---:|---:|---:|\n");
  for (int hz : {240, 480, 960, 1920}) {
    const double ms = ms_per_frame(hz, seconds);
    const DropError error = drop_errors(hz);
    fmt::print("| {} | {:.3f} | {:.2f} % | {:.2f} ms |\n", hz, ms, 100 * error.bounce_relative, 1e3 * error.landing_s);
  }
  return 0;
}

}  // namespace

void add_physics_benchmark(CLI::App& bench) {
  CLI::App* command = bench.add_subcommand(
      "physics", "rigid-body physics: run time per frame against bounce and landing error, per substep rate");
  auto seconds = std::make_shared<double>(10.0);
  command->add_option("--seconds", *seconds, "simulated seconds of the busy scene per row")->check(CLI::Range(0.1, 600.0));
  cli::on_run(command, [seconds] { return run_physics_benchmark(*seconds); }, cli::Failure{});
}

}  // namespace arpipe
