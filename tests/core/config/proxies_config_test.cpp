// The proxy, physics and rigid-body rows of a config ([[render.proxies]], [render.physics],
// [render.objects.physics]): read, defaulted, printed by --defaults, and refused with the place.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <numbers>
#include <string>
#include <vector>

#include "core/config/config.h"

namespace arpipe {
namespace {

void expect_proxy_error(const std::string& text, const std::vector<std::string>& fragments) {
  try {
    parse_config(text, "p.toml");
    ADD_FAILURE() << "expected a ConfigError for:\n" << text;
  } catch (const ConfigError& e) {
    const std::string message = e.what();
    for (const auto& fragment : fragments)
      EXPECT_NE(message.find(fragment), std::string::npos) << "'" << fragment << "' missing from: " << message;
  }
}

constexpr double kDeg = std::numbers::pi / 180;

TEST(ProxiesConfig, ReadsProxiesWithTheirRolesAndPlacement) {
  const Config c = parse_config(R"(
[[render.proxies]]
name = "table"
mesh = "builtin:box"
size_m = [1.2, 0.8, 0.75]
position_m = [0.1, 0.2, -0.75]
yaw_deg = 30
pitch_deg = 5
roll_deg = -2
roles = ["occlude", "collide"]
collider = "box"
restitution = 0.8
friction = 0.4

[[render.proxies]]
mesh = "builtin:cylinder"
)", "p.toml");
  ASSERT_EQ(c.render.proxies.size(), 2u);
  const SceneProxy& table = c.render.proxies[0];
  EXPECT_EQ(table.name, "table");
  EXPECT_EQ(table.size_m, (Vec3{1.2, 0.8, 0.75}));
  EXPECT_NEAR(table.yaw_rad, 30 * kDeg, 1e-15);
  EXPECT_NEAR(table.pitch_rad, 5 * kDeg, 1e-15);
  EXPECT_NEAR(table.roll_rad, -2 * kDeg, 1e-15);
  EXPECT_EQ(table.roles, (ProxyRoles{true, false, false, true}));
  EXPECT_EQ(table.collider, ColliderChoice::Box);
  EXPECT_EQ(table.restitution, 0.8);
  // Defaults: every role, the auto collider, the mesh itself for collisions.
  const SceneProxy& can = c.render.proxies[1];
  EXPECT_EQ(can.roles, ProxyRoles{});
  EXPECT_EQ(can.collider, ColliderChoice::Auto);
  EXPECT_TRUE(can.collision_mesh.empty());
  // An empty roles array: the proxy does nothing (allowed: a placeholder).
  const Config none = parse_config("[[render.proxies]]\nroles = []\n", "p.toml");
  EXPECT_EQ(none.render.proxies[0].roles, (ProxyRoles{false, false, false, false}));
}

TEST(ProxiesConfig, ReadsAThrownBallAndThePhysicsSettings) {
  const Config c = parse_config(R"(
[render.physics]
substep_hz = 480
gravity_mps2 = [0, 0, -9.81]
ground = false
max_advance_ms = 2000
history_ms = 250

[[render.objects]]
mesh = "builtin:sphere"
position_m = [0, 0, 0.3]
[render.objects.physics]
kind = "dynamic"
mass_kg = 0.05
velocity_mps = [1.5, 0, 1.0]
spin_deg_s = [0, 360, 0]
restitution = 0.7
shape = "sphere"

[[render.objects]]
mesh = "builtin:cube"
[render.objects.physics]
kind = "kinematic"
[[render.objects.physics.track]]
time_s = 0
position_m = [0, 0, 0]
[[render.objects.physics.track]]
time_s = 2
position_m = [0.5, 0, 0]
yaw_deg = 90
)", "p.toml");
  EXPECT_EQ(c.render.physics.substep_hz, 480);
  EXPECT_FALSE(c.render.physics.ground);
  EXPECT_EQ(c.render.physics.max_advance_ns, 2'000'000'000);
  EXPECT_EQ(c.render.physics.history_ns, 250'000'000);
  ASSERT_EQ(c.render.objects.size(), 2u);
  const ObjectPhysics& ball = c.render.objects[0].physics;
  EXPECT_EQ(ball.kind, ObjectMotion::Dynamic);
  EXPECT_EQ(ball.mass_kg, 0.05);
  EXPECT_EQ(ball.velocity_mps, (Vec3{1.5, 0, 1.0}));
  EXPECT_NEAR(ball.spin_radps[1], 2 * std::numbers::pi, 1e-12);
  EXPECT_EQ(ball.shape, BodyShapeChoice::Sphere);
  const ObjectPhysics& pusher = c.render.objects[1].physics;
  EXPECT_EQ(pusher.kind, ObjectMotion::Kinematic);
  ASSERT_EQ(pusher.track.size(), 2u);
  EXPECT_EQ(pusher.track[1].time_s, 2.0);
  EXPECT_NEAR(pusher.track[1].yaw_rad, std::numbers::pi / 2, 1e-15);
  // No physics table: the object is placed as configured.
  EXPECT_EQ(parse_config("[[render.objects]]\n", "p.toml").render.objects[0].physics.kind, ObjectMotion::None);
}

TEST(ProxiesConfig, RefusesBadRowsNamingThePlace) {
  expect_proxy_error("[[render.proxies]]\nroles = [\"occlude\", \"ocluded\"]\n",
                     {"p.toml:2", "render.proxies[0].roles", "\"ocluded\"", "\"receive_shadows\""});
  expect_proxy_error("[[render.proxies]]\nroles = [\"collide\", \"collide\"]\n", {"render.proxies[0].roles", "twice"});
  expect_proxy_error("[[render.proxies]]\nroles = \"occlude\"\n", {"render.proxies[0].roles", "an array"});
  expect_proxy_error("[[render.proxies]]\nsize_m = [0.1, -0.01, 0.1]\n", {"render.proxies[0].size_m"});
  expect_proxy_error("[[render.proxies]]\ncollider = \"mesh\"\n", {"render.proxies[0].collider", "\"triangles\""});
  expect_proxy_error("[[render.proxies]]\nmesh = \"\"\n", {"render.proxies[0].mesh"});
  expect_proxy_error("[[render.proxies]]\nwhatever = 1\n", {"render.proxies[0].whatever", "unknown key"});
  expect_proxy_error("[render.physics]\nsubstep_hz = 10\n", {"render.physics.substep_hz"});
  expect_proxy_error("[[render.objects]]\n[render.objects.physics]\nkind = \"floating\"\n",
                     {"render.objects[0].physics.kind", "\"dynamic\""});
  expect_proxy_error("[[render.objects]]\n[render.objects.physics]\nmass_kg = 0\n", {"render.objects[0].physics.mass_kg"});
  expect_proxy_error(
      "[[render.objects]]\n[render.objects.physics]\nkind = \"kinematic\"\n[[render.objects.physics.track]]\ntime_s = 1\n"
      "[[render.objects.physics.track]]\ntime_s = 1\n",
      {"render.objects[0].physics.track", "increase"});
  expect_proxy_error("[[render.objects]]\n[render.objects.physics]\nkind = \"dynamic\"\n[[render.objects.physics.track]]\n",
                     {"render.objects[0].physics.track", "kinematic"});
}

TEST(ProxiesConfig, ReadsAnAnimatedNodeAndRefusesItOnABuiltin) {
  const Config c = parse_config(R"(
[[render.proxies]]
mesh = "scene.glb"
skip_animated_nodes = true

[[render.proxies]]
mesh = "scene.glb"
node = "cart"
animation = "drive"
)", "p.toml");
  ASSERT_EQ(c.render.proxies.size(), 2u);
  EXPECT_TRUE(c.render.proxies[0].skip_animated_nodes);
  EXPECT_TRUE(c.render.proxies[0].node.empty());
  EXPECT_EQ(c.render.proxies[1].node, "cart");
  EXPECT_EQ(c.render.proxies[1].animation, "drive");
  EXPECT_FALSE(c.render.proxies[1].skip_animated_nodes);
  expect_proxy_error("[[render.proxies]]\nmesh = \"builtin:box\"\nnode = \"cart\"\n",
                     {"render.proxies[0].node", "glTF", "builtin:box"});
  expect_proxy_error("[[render.proxies]]\nskip_animated_nodes = true\n", {"render.proxies[0].skip_animated_nodes", "glTF"});
  expect_proxy_error("[[render.proxies]]\nmesh = \"a.glb\"\nnode = \"cart\"\nskip_animated_nodes = true\n",
                     {"render.proxies[0].skip_animated_nodes", "not both"});
}

TEST(ProxiesConfig, TheAnimatedHybridExampleReadsItsMovingProxy) {
  // configs/hybrid-animated.toml (its video and glTF are made by arpipe simulate, so only the text
  // is read here): the cart's proxy is the exported file's node "cart".
  std::ifstream in(std::string(ARPIPE_SOURCE_DIR) + "/configs/hybrid-animated.toml");
  std::stringstream text;
  text << in.rdbuf();
  const Config c = parse_config(text.str(), "hybrid-animated.toml");
  EXPECT_EQ(c.source.type, SourceType::Panorama);
  ASSERT_EQ(c.render.proxies.size(), 3u);
  EXPECT_EQ(c.render.proxies[2].name, "cart");
  EXPECT_EQ(c.render.proxies[2].node, "cart");
  EXPECT_FALSE(c.render.proxies[2].roles.collide);
}

// --defaults prints the rows (a commented-out proxy with every role) and reads back as the defaults.
TEST(ProxiesConfig, DefaultsListTheNewRows) {
  const std::string text = default_config_toml();
  for (const char* fragment : {"[[render.proxies]]", "roles = [\"occlude\", \"receive_shadows\", \"cast_shadows\", \"collide\"]",
                               "[render.physics]", "substep_hz = 960", "[render.objects.physics]", "kind = \"none\""})
    EXPECT_NE(text.find(fragment), std::string::npos) << fragment;
}

}  // namespace
}  // namespace arpipe
