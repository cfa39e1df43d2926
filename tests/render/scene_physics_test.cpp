// The config's rigid-body world (render/scene_physics.h) against closed forms: a dropped ball
// lands when free fall says, a thrown ball bounces off a proxy box where the geometry says (seed
// 003's scene C), replays repeat bit for bit, and a body that leaves the world is removed.
#include "render/scene_physics.h"

#include <gtest/gtest.h>

#include <cmath>

namespace arpipe {
namespace {

constexpr double kG = 9.80665;
constexpr int64_t kT0 = 5'000'000'000;       // the first frame's exposure start
constexpr int64_t kFrameNs = 33'333'333;      // 30 frames/s
constexpr int64_t kExposureNs = 10'000'000;

Config ball_config(const Vec3& position, const Vec3& velocity, double restitution) {
  Config config;
  SceneObject ball;
  ball.mesh = "builtin:sphere";  // radius 3 cm, base on z = 0 of its frame
  ball.prt = ObjectPrt::Off;
  ball.position_m = position;
  ball.physics.kind = ObjectMotion::Dynamic;
  ball.physics.velocity_mps = velocity;
  ball.physics.restitution = restitution;
  config.render.objects = {ball};
  return config;
}

// Runs frames up to `seconds` after kT0 as the render stage does.
void run_frames(ScenePhysics& physics, double seconds) {
  for (int64_t t = kT0; t <= kT0 + int64_t(seconds * 1e9); t += kFrameNs) physics.advance(t, t + kExposureNs);
}

// Dropped from 0.5 m (its base), it lands at sqrt(2 h / g) within a substep or two: before it
// falls, after it rises.
TEST(ScenePhysics, DroppedBallLandsWhenFreeFallSays) {
  const Config config = ball_config({0, 0, 0.5}, {0, 0, 0}, 0.5);
  ScenePhysics physics(config, load_object_meshes(config));
  ASSERT_FALSE(physics.empty());
  run_frames(physics, 0.45);
  const double landing_s = std::sqrt(2 * 0.5 / kG);
  const int64_t substep_ns = 1'000'000'000 / config.render.physics.substep_hz + 1;
  const int64_t landing = kT0 + std::llround(landing_s * 1e9);
  const std::optional<BodySample> before = physics.sample(0, landing - 2 * substep_ns);
  const std::optional<BodySample> after = physics.sample(0, landing + 2 * substep_ns);
  ASSERT_TRUE(before && after);
  EXPECT_LT(before->linear_velocity_mps[2], -0.9 * kG * landing_s);
  EXPECT_GT(after->linear_velocity_mps[2], 0);
  // Free fall before it: z = h - g t^2 / 2 at a quarter of the way down, less the first-order
  // term of Bullet's semi-implicit Euler (position from the new velocity: g t dt / 2, 0.8 mm
  // here); what remains is the interpolation between substeps, well under 0.2 mm.
  const double t = 0.5 * landing_s, dt = 1.0 / config.render.physics.substep_hz;
  const std::optional<BodySample> falling = physics.sample(0, kT0 + std::llround(t * 1e9));
  EXPECT_NEAR(falling->T_world_body.translation()[2], 0.5 - 0.5 * kG * t * t - 0.5 * kG * t * dt, 2e-4);
}

// A ball thrown at 2 m/s along x, without gravity or ground, at a real box whose -x face is at
// x = 0.4 (a proxy of `viewpoint`).
Config thrown_at_box_config(int viewpoint) {
  Config config = ball_config({0, 0, 0.1}, {2.0, 0, 0}, 0.8);
  config.render.physics.gravity_mps2 = {0, 0, 0};
  config.render.physics.ground = false;
  SceneProxy box;
  box.mesh = "builtin:box";
  box.size_m = {0.2, 0.4, 0.4};
  box.position_m = {0.5, 0, 0};
  box.viewpoint = viewpoint;
  config.render.proxies = {box};
  return config;
}

// Scene C: a ball thrown at a real box bounces off its face. Without gravity (and no ground) the
// closed form is simple: it reaches the face at x = face - r, and comes back at e times its speed.
TEST(ScenePhysics, ThrownBallBouncesOffAProxyBox) {
  const Config config = thrown_at_box_config(-1);
  ScenePhysics physics(config, load_object_meshes(config));
  run_frames(physics, 0.4);
  const double hit_s = (0.4 - 0.03) / 2.0;
  const std::optional<BodySample> early = physics.sample(0, kT0 + 100'000'000);
  EXPECT_NEAR(early->T_world_body.translation()[0], 0.2, 1e-6);
  const std::optional<BodySample> late = physics.sample(0, kT0 + 380'000'000);
  ASSERT_TRUE(late && late->present);
  EXPECT_NEAR(late->linear_velocity_mps[0], -1.6, 0.016);  // restitution 0.8 within 1 %
  // Back from the face by the rebound speed times the time since the hit (one substep: 2 mm).
  EXPECT_NEAR(late->T_world_body.translation()[0], 0.37 - 1.6 * (0.38 - hit_s), 3e-3);
}

// The same frames give bit-identical trajectories, in two worlds or in one replayed from its start.
// A proxy of one panorama viewpoint (render.proxies.viewpoint) stops bodies only while the view is
// there: at another viewpoint the thrown ball flies on through where the box stands.
TEST(ScenePhysics, AProxyStopsBodiesOnlyAtItsOwnViewpoint) {
  const Config config = thrown_at_box_config(1);
  const auto x_after = [&](std::optional<int> viewpoint) {
    ScenePhysics physics(config, load_object_meshes(config));
    for (int64_t t = kT0; t <= kT0 + 400'000'000; t += kFrameNs) {
      physics.set_viewpoint(viewpoint);
      physics.advance(t, t + kExposureNs);
    }
    return physics.sample(0, kT0 + 380'000'000)->T_world_body.translation()[0];
  };
  // On through: 2 m/s for 0.38 s, within the rounding of Bullet's float state over 365 substeps
  // (an ulp at 0.76 m is 6e-8 m).
  EXPECT_NEAR(x_after(0), 0.76, 2e-5);
  EXPECT_LT(x_after(1), 0.37);                    // bounced back off the face (the test above)
  EXPECT_NEAR(x_after(std::nullopt), x_after(1), 1e-12);  // a frame without a viewpoint: every collider
  // Leaving the viewpoint mid-flight (before the hit at 0.185 s) lets it through.
  ScenePhysics physics(config, load_object_meshes(config));
  for (int64_t t = kT0; t <= kT0 + 400'000'000; t += kFrameNs) {
    physics.set_viewpoint(t < kT0 + 100'000'000 ? 1 : 2);
    physics.advance(t, t + kExposureNs);
  }
  EXPECT_NEAR(physics.sample(0, kT0 + 380'000'000)->T_world_body.translation()[0], 0.76, 2e-5);
}

TEST(ScenePhysics, ReplaysRepeatBitForBit) {
  const Config config = ball_config({0.0, 0.0, 0.3}, {0.4, 0.2, 0.5}, 0.6);
  const LoadedMeshes meshes = load_object_meshes(config);
  ScenePhysics a(config, meshes), b(config, meshes);
  run_frames(a, 1.0);
  run_frames(b, 1.0);
  const int64_t end = kT0 + 990'000'000;
  const SE3 first = a.sample(0, end)->T_world_body;
  EXPECT_EQ(first.translation(), b.sample(0, end)->T_world_body.translation());
  EXPECT_EQ(first.rotation(), b.sample(0, end)->T_world_body.rotation());
  run_frames(a, 1.0);  // the replay starts again: the world is built afresh at its first frame
  EXPECT_EQ(a.restarts(), 1);
  EXPECT_EQ(first.translation(), a.sample(0, end)->T_world_body.translation());
}

TEST(ScenePhysics, ABodyThatLeavesTheWorldIsRemovedAndCounted) {
  Config config = ball_config({0, 0, 0.1}, {50, 0, 0}, 0.5);
  config.render.physics.world_radius_m = 2.0;
  ScenePhysics physics(config, load_object_meshes(config));
  run_frames(physics, 0.2);
  const std::optional<BodySample> gone = physics.sample(0, kT0 + 190'000'000);
  ASSERT_TRUE(gone);
  EXPECT_FALSE(gone->present);
  ASSERT_NE(physics.stats(), nullptr);
  EXPECT_EQ(physics.stats()->removed_beyond_radius, 1u);
}

TEST(ScenePhysics, NothingMovesWithoutAPhysicsKind) {
  Config config = ball_config({0, 0, 0.1}, {0, 0, 0}, 0.5);
  config.render.objects[0].physics.kind = ObjectMotion::None;
  EXPECT_TRUE(ScenePhysics(config, load_object_meshes(config)).empty());
}

}  // namespace
}  // namespace arpipe
