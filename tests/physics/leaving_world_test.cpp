// Bodies that leave the world are removed and counted with their reason, and queries about them
// keep working; huge time jumps are capped and said so; unusable times are ignored and counted.
#include <gtest/gtest.h>

#include <limits>

#include "tests/physics/physics_test_scenes.h"

namespace arpipe {
namespace {

using namespace physics_test;

TEST(LeavingWorld, ABallThrownFarAwayIsRemovedBeyondTheRadius) {
  RigidWorldSettings settings;
  settings.world_radius_m = 20;
  RigidWorld world(settings);
  world.add_collider(ground());
  RigidBodySpec thrown = ball({0, 0, 1}, 0.05, 0.5);
  thrown.linear_velocity_mps = {40, 0, 5};
  const size_t id = world.add_body(thrown);
  const size_t stays = world.add_body(ball({0, 1, 0.05}, 0.05, 0.5));
  world.start(kStartNs);
  size_t removed = 0;
  for (int frame = 1; frame <= 60; ++frame) removed += world.advance_to(kStartNs + frame * 33'333'333).removed;
  EXPECT_EQ(removed, 1u);
  EXPECT_EQ(world.removal(id), RemovalReason::BeyondRadius);
  EXPECT_EQ(world.removal(stays), RemovalReason::None);
  EXPECT_EQ(world.stats().removed_beyond_radius, 1u);
  EXPECT_STREQ(removal_reason_name(world.removal(id)), "beyond_radius");
  EXPECT_FALSE(world.sample_at(id, world.newest_ns()).present);
  EXPECT_TRUE(world.sample_at(stays, world.newest_ns()).present);
  // 20 m at 40 m/s: gone after about half a second, present before.
  EXPECT_TRUE(world.sample_at(id, kStartNs).present || world.oldest_ns() > kStartNs);
}

TEST(LeavingWorld, ABallWithNothingUnderItFallsBelowTheFloorLimit) {
  RigidWorldSettings settings;
  settings.history_ns = 3'000'000'000;
  RigidWorld world(settings);
  const size_t id = world.add_body(ball({0, 0, 1}, 0.05, 0.5));
  world.start(kStartNs);
  world.advance_to(kStartNs + 2'000'000'000);
  EXPECT_EQ(world.removal(id), RemovalReason::BelowFloor);
  EXPECT_EQ(world.stats().removed_below_floor, 1u);
  // z = 1 - g t^2 / 2 crosses -10 m at t = sqrt(22 / g) = 1.498 s.
  const double t_gone = std::sqrt(2 * 11 / kG);
  EXPECT_TRUE(world.sample_at(id, kStartNs + static_cast<int64_t>((t_gone - 0.02) * 1e9)).present);
  EXPECT_FALSE(world.sample_at(id, kStartNs + static_cast<int64_t>((t_gone + 0.02) * 1e9)).present);
  // Advancing further with the body gone is fine.
  world.advance_to(kStartNs + 3'000'000'000);
  EXPECT_EQ(world.stats().removed_below_floor, 1u);
}

TEST(LeavingWorld, AJumpOfHoursIsCappedAndTheRestFrozen) {
  RigidWorldSettings settings;
  settings.max_substeps_per_advance = settings.substep_hz;  // one second
  RigidWorld world(settings);
  world.add_collider(ground());
  const size_t id = world.add_body(ball({0, 0, 0.05}, 0.05, 0.5));
  world.start(kStartNs);
  const int64_t hour = 3600LL * 1'000'000'000;
  const AdvanceResult r = world.advance_to(kStartNs + hour);
  EXPECT_EQ(r.substeps, settings.substep_hz);
  EXPECT_EQ(r.frozen_ns, hour - 1'000'000'000);
  EXPECT_EQ(world.stats().capped_advances, 1);
  EXPECT_EQ(world.stats().frozen_ns, hour - 1'000'000'000);
  EXPECT_EQ(world.newest_ns(), kStartNs + hour);
  // The grid restarts at the jump's end; the next frame runs normally.
  const AdvanceResult next = world.advance_to(kStartNs + hour + 33'333'333);
  EXPECT_EQ(next.substeps, 32);  // 33.3 ms at 960 Hz
  EXPECT_EQ(next.frozen_ns, 0);
  const BodySample s = world.sample_at(id, world.newest_ns());
  EXPECT_TRUE(s.present);
  EXPECT_NEAR(s.T_world_body.translation()[2], 0.05, 1e-3);
}

TEST(LeavingWorld, UnusableAndBackwardTimesChangeNothing) {
  RigidWorld world;
  world.add_body(ball({0, 0, 1}, 0.05, 0.5));
  EXPECT_TRUE(world.advance_to(std::numeric_limits<int64_t>::max()).ignored);
  EXPECT_FALSE(world.started());
  world.advance_to(kStartNs);
  EXPECT_TRUE(world.advance_to(std::numeric_limits<int64_t>::min()).ignored);
  EXPECT_EQ(world.stats().ignored_times, 2);
  world.advance_to(kStartNs + 100'000'000);
  const int64_t steps = world.stats().substeps;
  EXPECT_EQ(world.advance_to(kStartNs + 50'000'000).substeps, 0);
  EXPECT_EQ(world.stats().substeps, steps);
}

TEST(LeavingWorld, QueriesOutsideTheKeptSpanAreClampedAndSaidSo) {
  RigidWorldSettings settings;
  settings.history_ns = 100'000'000;
  RigidWorld world(settings);
  const size_t id = world.add_body(ball({0, 0, 100}, 0.05, 0.5));
  EXPECT_TRUE(world.sample_at(id, 0).clamped);  // before the start: the initial pose
  EXPECT_EQ(world.pose_at(id, 0).translation()[2], 100);
  world.start(kStartNs);
  world.advance_to(kStartNs + 1'000'000'000);
  EXPECT_TRUE(world.sample_at(id, kStartNs).clamped);
  EXPECT_TRUE(world.sample_at(id, world.newest_ns() + 1).clamped);
  EXPECT_FALSE(world.sample_at(id, world.newest_ns() - 50'000'000).clamped);
  EXPECT_GE(world.newest_ns() - world.oldest_ns(), 100'000'000);
  EXPECT_THROW(world.sample_at(7, kStartNs), std::out_of_range);
}

TEST(LeavingWorld, ABodyAddedLaterEntersAtTheNewestSubstep) {
  RigidWorld world;
  world.add_collider(ground());
  world.start(kStartNs);
  world.advance_to(kStartNs + 200'000'000);
  const int64_t entered = world.newest_ns();
  const size_t id = world.add_body(ball({0, 0, 1}, 0.05, 0.5));
  EXPECT_TRUE(world.sample_at(id, entered).present);
  EXPECT_FALSE(world.sample_at(id, entered - 1).present);
  world.advance_to(entered + 300'000'000);
  const double t = 0.3;
  EXPECT_NEAR(world.pose_at(id, entered + 300'000'000).translation()[2], 1 - kG * t * t / 2, 0.01);
}

TEST(LeavingWorld, AKinematicBodyFollowsItsTrackAndPushesABall) {
  RigidWorld world;
  world.add_collider(ground(1.0, 0.0));
  RigidBodySpec pusher;
  pusher.name = "pusher";
  pusher.kind = BodyKind::Kinematic;
  pusher.shape = BoxShape{{0.05, 0.2, 0.05}};
  pusher.track = {{kStartNs, at({-0.5, 0, 0.05})}, {kStartNs + 1'000'000'000, at({0.5, 0, 0.05})}};
  const size_t p = world.add_body(pusher);
  const size_t b = world.add_body(ball({0, 0, 0.05}, 0.05, 0.0, 0.0));
  world.start(kStartNs);
  world.advance_to(kStartNs + 500'000'000);
  EXPECT_NEAR(world.pose_at(p, kStartNs + 250'000'000).translation()[0], -0.25, 1e-6);
  world.advance_to(kStartNs + 1'500'000'000);
  EXPECT_NEAR(world.pose_at(p, world.newest_ns()).translation()[0], 0.5, 1e-6);
  // The paddle at 1 m/s hit the ball (restitution 0): it moves off at least as fast.
  EXPECT_GT(world.pose_at(b, world.newest_ns()).translation()[0], 0.6);
}

}  // namespace
}  // namespace arpipe
