// glTF node animations (core/scene/gltf_animation.h) against hand-worked answers: STEP, LINEAR
// (slerp the short way) and CUBICSPLINE (Hermite, tangents scaled by the key interval) on
// hand-written files, the end keys held outside their range, a child under an animated parent,
// node_pose_at against where load_gltf_mesh puts the whole scene's vertices, skip_animated, lights
// moving with their node, and the .glb writer's animated nodes read back at and between the keys.
// Tolerances: 1e-6 (m, rad) where float keys and vertices are all that differ; 1e-4 for rotations
// stored as normalised 16-bit integers.
#include "core/scene/gltf_animation.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <numbers>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/scene/asset_error.h"
#include "core/scene/glb_writer.h"
#include "tests/scene/gltf_hostile_files.h"

namespace arpipe {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using render_test::AnimatedGltf;
using render_test::one_channel_animation;

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr double kTolerance = 1e-6;  // metres and radians

// glTF's (x, y, z, w) of a rotation by `degrees` about the unit axis (glTF's axes).
std::vector<float> quaternion(double degrees, std::array<double, 3> axis) {
  const double half = 0.5 * degrees * kDeg;
  return {float(std::sin(half) * axis[0]), float(std::sin(half) * axis[1]), float(std::sin(half) * axis[2]),
          float(std::cos(half))};
}

// A rotation about the object's (z-up) axis by `degrees`, and a translation.
SE3 object_pose(double degrees, const Vec3& axis, const Vec3& t) { return SE3::from_rt((degrees * kDeg) * axis, t); }

void expect_pose(const ScaledPose& placed, const SE3& expected, double scale = 1.0, double tolerance = kTolerance) {
  EXPECT_LT(norm(placed.pose.translation() - expected.translation()), tolerance)
      << "at (" << placed.pose.translation()[0] << ", " << placed.pose.translation()[1] << ", "
      << placed.pose.translation()[2] << ")";
  EXPECT_LT(rotation_angle_between(placed.pose, expected), tolerance);
  EXPECT_NEAR(placed.scale, scale, tolerance);
}

std::vector<float> concat(std::initializer_list<std::vector<float>> parts) {
  std::vector<float> out;
  for (const auto& part : parts) out.insert(out.end(), part.begin(), part.end());
  return out;
}

Vec3 vertex(const Mesh& mesh, size_t v) { return {mesh.positions[3 * v], mesh.positions[3 * v + 1], mesh.positions[3 * v + 2]}; }
Vec3 normal(const Mesh& mesh, size_t v) { return {mesh.normals[3 * v], mesh.normals[3 * v + 1], mesh.normals[3 * v + 2]}; }

std::set<std::array<float, 4>> colours(const Mesh& mesh) {
  std::set<std::array<float, 4>> out;
  for (const MeshPart& part : mesh.parts) out.insert(part.base_color);
  return out;
}

class GltfAnimationTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(ARPIPE_BINARY_DIR) / "test_tmp" / "gltf_animation" /
           ::testing::UnitTest::GetInstance()->current_test_info()->name();
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  fs::path write(const std::string& name, const json& gltf) {
    render_test::write_file(dir_ / name, gltf.dump());
    return dir_ / name;
  }
  fs::path write_glb(const std::string& name, const std::vector<uint8_t>& bytes) {
    render_test::write_file(dir_ / name, std::string(bytes.begin(), bytes.end()));
    return dir_ / name;
  }
  fs::path dir_;
};

// STEP: each key's value holds until the next key's time.
TEST_F(GltfAnimationTest, StepHoldsEachKeyUntilTheNext) {
  AnimatedGltf file;
  file.gltf["nodes"] = {{{"mesh", 0}, {"name", "mover"}}};
  const int times = file.floats({0, 1, 2}, "SCALAR");
  const int values = file.floats({0, 0, 0, 1, 2, 3, 2, 4, 6}, "VEC3");  // key k: glTF (k, 2k, 3k)
  file.gltf["animations"] = {one_channel_animation(0, "translation", times, values, "STEP")};
  const GltfAnimation animation = GltfAnimation::load(write("step.gltf", file.done()));
  EXPECT_EQ(animation.duration_s(), 2.0);
  const int node = *animation.find_node("mover");
  // glTF (k, 2k, 3k) is the object's (k, -3k, 2k).
  for (const auto& [t, k] : std::vector<std::pair<double, double>>{{-1, 0}, {0, 0}, {0.5, 0}, {0.999, 0}, {1, 1},
                                                                    {1.5, 1}, {1.999, 1}, {2, 2}, {3, 2}}) {
    SCOPED_TRACE(t);
    expect_pose(animation.node_pose_at(node, t), SE3(identity3(), {k, -3 * k, 2 * k}));
  }
}

// LINEAR: translation straight, rotation slerped; glTF's rotation about y is the object's about z.
TEST_F(GltfAnimationTest, LinearInterpolatesTranslationAndSlerpsRotation) {
  AnimatedGltf file;
  file.gltf["nodes"] = {{{"mesh", 0}, {"name", "mover"}}};
  const int times = file.floats({0, 2}, "SCALAR");
  const int moves = file.floats({0, 0, 0, 2, 4, 6}, "VEC3");
  const int turns = file.floats(concat({quaternion(0, {0, 1, 0}), quaternion(90, {0, 1, 0})}), "VEC4");
  json animation = one_channel_animation(0, "translation", times, moves);
  animation["samplers"].push_back({{"input", times}, {"output", turns}});  // LINEAR by default
  animation["channels"].push_back({{"sampler", 1}, {"target", {{"node", 0}, {"path", "rotation"}}}});
  file.gltf["animations"] = {animation};
  const GltfAnimation loaded = GltfAnimation::load(write("linear.gltf", file.done()));
  for (double t : {0.0, 0.5, 1.0, 1.7, 2.0}) {
    SCOPED_TRACE(t);
    const double s = t / 2;  // glTF (2s, 4s, 6s) is the object's (2s, -6s, 4s)
    expect_pose(loaded.node_pose_at(0, t), object_pose(90 * s, {0, 0, 1}, {2 * s, -6 * s, 4 * s}));
  }
}

// glTF's slerp goes the short way: a second key of the other sign is the same rotation, and the
// halfway point is 45 degrees, not 135 degrees the other way round.
TEST_F(GltfAnimationTest, LinearRotationTakesTheShortWayWhenTheKeysDisagreeInSign) {
  AnimatedGltf file;
  file.gltf["nodes"] = {{{"mesh", 0}}};
  std::vector<float> negated = quaternion(90, {0, 1, 0});
  for (float& c : negated) c = -c;
  const int times = file.floats({0, 2}, "SCALAR");
  const int turns = file.floats(concat({quaternion(0, {0, 1, 0}), negated}), "VEC4");
  file.gltf["animations"] = {one_channel_animation(0, "rotation", times, turns)};
  const GltfAnimation loaded = GltfAnimation::load(write("short.gltf", file.done()));
  expect_pose(loaded.node_pose_at(0, 1), object_pose(45, {0, 0, 1}, {0, 0, 0}));
  expect_pose(loaded.node_pose_at(0, 2), object_pose(90, {0, 0, 1}, {0, 0, 0}));
}

// CUBICSPLINE: p(s) = h00 v0 + td h10 b0 + h01 v1 + td h11 a1 with td the key interval (2 s), the
// values the middle of each (in-tangent, value, out-tangent) triple; rotations normalised.
TEST_F(GltfAnimationTest, CubicSplineIsHermiteWithTangentsScaledByTheKeyInterval) {
  AnimatedGltf file;
  file.gltf["nodes"] = {{{"mesh", 0}}};
  const int times = file.floats({0, 2}, "SCALAR");
  // a0 (unused), v0, b0, a1, v1, b1 (unused).
  const int moves = file.floats({9, 9, 9, 0, 0, 0, 1, 0, 0, 0, 0, 4, 1, 2, 0, 9, 9, 9}, "VEC3");
  const std::vector<float> zero{0, 0, 0, 0};
  const int turns = file.floats(concat({zero, quaternion(0, {0, 1, 0}), zero, zero, quaternion(90, {0, 1, 0}), zero}), "VEC4");
  json animation = one_channel_animation(0, "translation", times, moves, "CUBICSPLINE");
  animation["samplers"].push_back({{"input", times}, {"output", turns}, {"interpolation", "CUBICSPLINE"}});
  animation["channels"].push_back({{"sampler", 1}, {"target", {{"node", 0}, {"path", "rotation"}}}});
  file.gltf["animations"] = {animation};
  const GltfAnimation loaded = GltfAnimation::load(write("cubic.gltf", file.done()));
  // t = 0.5: s = 0.25, h00 = 0.84375, h10 = 0.140625, h01 = 0.15625, h11 = -0.046875:
  // x = 2 * 0.140625 + 0.15625 = 0.4375, y = 0.15625 * 2 = 0.3125, z = 2 * -0.046875 * 4 = -0.375
  // (glTF), the object's (0.4375, 0.375, 0.3125). The rotation: the unit vector along
  // 0.84375 q0 + 0.15625 q1 (zero tangents): atan2 of the two's sin and cos parts, twice.
  const double half = std::atan2(0.15625 * std::sin(45 * kDeg), 0.84375 + 0.15625 * std::cos(45 * kDeg));
  expect_pose(loaded.node_pose_at(0, 0.5), SE3::from_rt({0, 0, 2 * half}, {0.4375, 0.375, 0.3125}));
  // t = 1: s = 0.5, h00 = h01 = 0.5, h10 = 0.125, h11 = -0.125: x = 0.25 + 0.5 = 0.75, y = 1,
  // z = -1; the rotation halfway, 45 degrees.
  expect_pose(loaded.node_pose_at(0, 1), object_pose(45, {0, 0, 1}, {0.75, 1, 1}));
  expect_pose(loaded.node_pose_at(0, 2), object_pose(90, {0, 0, 1}, {1, 0, 2}));
}

// Before the first key and after the last, the end keys hold (the first key here is at 1 s).
TEST_F(GltfAnimationTest, EndKeysHoldBeforeTheFirstAndAfterTheLastKey) {
  for (const std::string interpolation : {"STEP", "LINEAR", "CUBICSPLINE"}) {
    SCOPED_TRACE(interpolation);
    AnimatedGltf file;
    file.gltf["nodes"] = {{{"mesh", 0}}};
    const int times = file.floats({1, 3}, "SCALAR");
    const std::vector<float> first{0, 0, 0}, last{2, 0, 0}, flat{0, 0, 0};
    const int moves = file.floats(interpolation == "CUBICSPLINE" ? concat({flat, first, flat, flat, last, flat}) : concat({first, last}), "VEC3");
    file.gltf["animations"] = {one_channel_animation(0, "translation", times, moves, interpolation)};
    const GltfAnimation loaded = GltfAnimation::load(write("clamp.gltf", file.done()));
    EXPECT_EQ(loaded.duration_s(), 3.0);
    for (double t : {-5.0, 0.0, 1.0}) expect_pose(loaded.node_pose_at(0, t), SE3(identity3(), {0, 0, 0}));
    for (double t : {3.0, 3.5, 100.0, std::numeric_limits<double>::infinity()}) expect_pose(loaded.node_pose_at(0, t), SE3(identity3(), {2, 0, 0}));
  }
}

// The arm turns 90 degrees about glTF's y and rises 1 m over a second; the hand sits 1 m along the
// arm's x. At t: the hand at T(0, t, 0) R_y(90 t) (1, 0, 0) = (cos, t, -sin) in glTF, the object's
// (cos, sin, t); its rotation the arm's.
AnimatedGltf arm_and_hand() {
  AnimatedGltf file;
  file.gltf["nodes"] = {{{"name", "arm"}, {"children", {1}}},
                        {{"name", "hand"}, {"mesh", 0}, {"translation", {1, 0, 0}}},
                        {{"name", "post"}, {"mesh", 0}}};
  file.gltf["scenes"] = {{{"nodes", {0, 2}}}};
  const int times = file.floats({0, 1}, "SCALAR");
  const int rises = file.floats({0, 0, 0, 0, 1, 0}, "VEC3");
  const int turns = file.floats(concat({quaternion(0, {0, 1, 0}), quaternion(90, {0, 1, 0})}), "VEC4");
  json animation = one_channel_animation(0, "rotation", times, turns);
  animation["samplers"].push_back({{"input", times}, {"output", rises}});
  animation["channels"].push_back({{"sampler", 1}, {"target", {{"node", 0}, {"path", "translation"}}}});
  file.gltf["animations"] = {animation};
  return file;
}

TEST_F(GltfAnimationTest, AChildMovesWithItsAnimatedParent) {
  const GltfAnimation animation = GltfAnimation::load(write("arm.gltf", arm_and_hand().done()));
  const int hand = *animation.find_node("hand");
  EXPECT_TRUE(animation.moves(*animation.find_node("arm")));
  EXPECT_TRUE(animation.moves(hand));
  EXPECT_FALSE(animation.moves(*animation.find_node("post")));
  for (double t : {0.0, 0.25, 0.5, 1.0}) {
    SCOPED_TRACE(t);
    const double a = 90 * t * kDeg;
    expect_pose(animation.node_pose_at(hand, t), SE3::from_rt({0, 0, a}, {std::cos(a), std::sin(a), t}));
  }
}

// The scene of the next two tests: base (static), arm (animated, scale 2) > hand > finger, each a
// mesh of its own colour; the animation's first keys are the arm's rest TRS.
AnimatedGltf posed_scene() {
  AnimatedGltf file;
  const int red = file.coloured_mesh(1, 0, 0), green = file.coloured_mesh(0, 1, 0);
  const int blue = file.coloured_mesh(0, 0, 1), yellow = file.coloured_mesh(1, 1, 0);
  const std::vector<float> arm_turn = quaternion(30, {0.6, 0, 0.8}), hand_turn = quaternion(90, {0, 0, 1});
  file.gltf["nodes"] = {
      {{"name", "base"}, {"mesh", red}, {"translation", {0, 0, -1}}},
      {{"name", "arm"}, {"mesh", yellow}, {"children", {2}}, {"translation", {0.5, 0, 0}}, {"rotation", arm_turn}, {"scale", {2, 2, 2}}},
      {{"name", "hand"}, {"mesh", green}, {"children", {3}}, {"translation", {0, 1, 0}}, {"rotation", hand_turn}},
      {{"name", "finger"}, {"mesh", blue}, {"translation", {1, 0, 0}}, {"scale", {0.5, 0.5, 0.5}}}};
  file.gltf["scenes"] = {{{"nodes", {0, 1}}}};
  const int times = file.floats({0, 1}, "SCALAR");
  const int moves = file.floats({0.5, 0, 0, 1.5, 0, 0}, "VEC3");
  const int turns = file.floats(concat({arm_turn, quaternion(120, {0, 1, 0})}), "VEC4");
  json animation = one_channel_animation(1, "translation", times, moves);
  animation["samplers"].push_back({{"input", times}, {"output", turns}});
  animation["channels"].push_back({{"sampler", 1}, {"target", {{"node", 1}, {"path", "rotation"}}}});
  file.gltf["animations"] = {animation};
  return file;
}

// The node's subtree loaded in its own frame and placed at node_pose_at(node, 0) is the whole
// scene's copy of it: vertices within 1e-6 m, normals within 1e-6.
TEST_F(GltfAnimationTest, ANodesMeshPlacedAtItsPoseIsTheWholeScenesCopy) {
  const fs::path path = write("posed.gltf", posed_scene().done());
  const Mesh whole = load_gltf_mesh(path);
  const GltfAnimation animation = GltfAnimation::load(path);
  ASSERT_EQ(whole.vertex_count(), 12u);  // base, arm, hand, finger: three vertices each, in that order
  for (const auto& [name, first] : std::vector<std::pair<std::string, size_t>>{{"arm", 3}, {"hand", 6}, {"finger", 9}}) {
    SCOPED_TRACE(name);
    const Mesh alone = load_gltf_mesh(path, GltfMeshSelection{name, false});
    ASSERT_EQ(alone.vertex_count(), whole.vertex_count() - first);
    const ScaledPose placed = animation.node_pose_at(*animation.find_node(name), 0);
    EXPECT_NEAR(placed.scale, name == "finger" ? 1.0 : 2.0, 1e-12);  // the arm's 2, the finger's 0.5 on it
    for (size_t v = 0; v < alone.vertex_count(); ++v) {
      EXPECT_LT(norm(placed.pose * (placed.scale * vertex(alone, v)) - vertex(whole, first + v)), kTolerance) << v;
      EXPECT_LT(norm(placed.pose.rotate(normal(alone, v)) - normal(whole, first + v)), kTolerance) << v;
    }
  }
}

// skip_animated leaves out the subtrees of the nodes any animation's translation, rotation or
// scale channel targets, and nothing else: a weights channel moves nothing.
TEST_F(GltfAnimationTest, SkipAnimatedLeavesOutExactlyTheMovingSubtrees) {
  AnimatedGltf file;
  const int red = file.coloured_mesh(1, 0, 0), green = file.coloured_mesh(0, 1, 0), blue = file.coloured_mesh(0, 0, 1);
  const int yellow = file.coloured_mesh(1, 1, 0), magenta = file.coloured_mesh(1, 0, 1), cyan = file.coloured_mesh(0, 1, 1);
  const int grey = file.coloured_mesh(0.5, 0.5, 0.5);
  file.gltf["nodes"] = {{{"name", "base"}, {"mesh", red}},
                        {{"name", "arm"}, {"mesh", green}, {"children", {2}}},
                        {{"name", "hand"}, {"mesh", blue}},
                        {{"name", "post"}, {"mesh", yellow}, {"children", {4}}},
                        {{"name", "flag"}, {"mesh", magenta}, {"children", {5}}},
                        {{"name", "cloth"}, {"mesh", cyan}},
                        {{"name", "door"}, {"mesh", grey}}};
  file.gltf["scenes"] = {{{"nodes", {0, 1, 3, 6}}}};
  const int times = file.floats({0, 1}, "SCALAR");
  const int moves = file.floats({0, 0, 0, 1, 0, 0}, "VEC3");
  const int turns = file.floats(concat({quaternion(0, {1, 0, 0}), quaternion(10, {1, 0, 0})}), "VEC4");
  json first = one_channel_animation(1, "translation", times, moves);
  first["samplers"].push_back({{"input", times}, {"output", turns}});
  first["channels"].push_back({{"sampler", 1}, {"target", {{"node", 4}, {"path", "rotation"}}}});
  first["channels"].push_back({{"sampler", 0}, {"target", {{"node", 0}, {"path", "weights"}}}});
  json second = one_channel_animation(6, "scale", times, moves);
  second["name"] = "second";
  file.gltf["animations"] = {first, second};
  const fs::path path = write("skip.gltf", file.done());

  const Mesh still = load_gltf_mesh(path, GltfMeshSelection{"", true});
  EXPECT_EQ(still.triangle_count(), 2u);
  EXPECT_EQ(colours(still), (std::set<std::array<float, 4>>{{1, 0, 0, 1}, {1, 1, 0, 1}}));  // base and post
  EXPECT_EQ(load_gltf_mesh(path).triangle_count(), 7u);
  const GltfAnimation animation = GltfAnimation::load(path);
  EXPECT_FALSE(animation.moves(*animation.find_node("door")));  // the second animation's
  EXPECT_TRUE(animation.moves(*animation.find_node("cloth")));
  EXPECT_FALSE(animation.moves(*animation.find_node("base")));
  EXPECT_TRUE(GltfAnimation::load(path, "second").moves(6));
}

// A point light on the hand of arm_and_hand moves with it; at t = 0 the records are
// load_gltf_lights's, field by field; a directional light on a still node stays.
TEST_F(GltfAnimationTest, LightsAtMovesALightOnAnAnimatedNode) {
  AnimatedGltf file = arm_and_hand();
  file.gltf["extensions"] = {{"KHR_lights_punctual",
                              {{"lights", {{{"type", "point"}, {"name", "lamp"}, {"intensity", 5}},
                                           {{"type", "directional"}, {"name", "sun"}, {"intensity", 2}}}}}}};
  file.gltf["nodes"][1]["extensions"] = {{"KHR_lights_punctual", {{"light", 0}}}};
  file.gltf["nodes"][2]["extensions"] = {{"KHR_lights_punctual", {{"light", 1}}}};
  file.gltf["nodes"][2]["rotation"] = quaternion(-90, {1, 0, 0});  // shining down: glTF's -y
  const fs::path path = write("lamp.gltf", file.done());
  const GltfAnimation animation = GltfAnimation::load(path);
  const std::vector<GltfLight> at_rest = load_gltf_lights(path), at_zero = animation.lights_at(0);
  ASSERT_EQ(at_zero.size(), 2u);
  ASSERT_EQ(at_rest.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(at_zero[i].name, at_rest[i].name);
    EXPECT_EQ(at_zero[i].type, at_rest[i].type);
    EXPECT_EQ(at_zero[i].intensity, at_rest[i].intensity);
    EXPECT_EQ(at_zero[i].node, at_rest[i].node);
    EXPECT_LT(norm(at_zero[i].position - at_rest[i].position), 1e-12);
    EXPECT_LT(norm(at_zero[i].direction - at_rest[i].direction), 1e-12);
  }
  // t = 1: the lamp at the object's (0, 1, 1); its -z (glTF) turned by R_y(90) is glTF's -x, the
  // object's -x. The sun shines down (the object's -z) throughout.
  const std::vector<GltfLight> later = animation.lights_at(1);
  ASSERT_EQ(later.size(), 2u);
  EXPECT_EQ(later[0].name, "lamp");
  EXPECT_LT(norm(later[0].position - Vec3{0, 1, 1}), kTolerance);
  EXPECT_LT(norm(later[0].direction - Vec3{-1, 0, 0}), kTolerance);
  EXPECT_LT(norm(later[1].direction - Vec3{0, 0, -1}), kTolerance);
}

// Rotations as normalised SHORT (glTF allows it for rotations): the same as floats to 1/32767.
TEST_F(GltfAnimationTest, NormalisedShortRotationsReadAsFloats) {
  AnimatedGltf file;
  file.gltf["nodes"] = {{{"mesh", 0}}};
  const int times = file.floats({0, 1}, "SCALAR");
  const auto to_short = [](const std::vector<float>& q) {
    std::vector<int16_t> out;
    for (float c : q) out.push_back(int16_t(std::lround(c * 32767.0f)));
    return out;
  };
  std::vector<int16_t> keys = to_short(quaternion(0, {0, 1, 0}));
  for (int16_t c : to_short(quaternion(90, {0, 1, 0}))) keys.push_back(c);
  file.gltf["animations"] = {one_channel_animation(0, "rotation", times, file.normalized_shorts(keys))};
  const GltfAnimation loaded = GltfAnimation::load(write("shorts.gltf", file.done()));
  expect_pose(loaded.node_pose_at(0, 0.5), object_pose(45, {0, 0, 1}, {0, 0, 0}), 1.0, 1e-4);
}

// A file without animations: every node at rest, duration 0, nothing moves; a named animation
// chosen among several.
TEST_F(GltfAnimationTest, AFileWithoutAnimationsIsAtRestAndNamedAnimationsAreChosen) {
  AnimatedGltf still;
  still.gltf["nodes"][0]["name"] = "tri";
  const GltfAnimation rest = GltfAnimation::load(write("still.gltf", still.done()));
  EXPECT_EQ(rest.name(), "");
  EXPECT_EQ(rest.duration_s(), 0.0);
  EXPECT_FALSE(rest.moves(0));
  // triangle_json's node: translation (0, 0, 2), scale 0.5: the object's (0, -2, 0).
  expect_pose(rest.node_pose_at(0, 7), SE3(identity3(), {0, -2, 0}), 0.5);
  EXPECT_FALSE(rest.find_node("nothing").has_value());

  AnimatedGltf file;
  file.gltf["nodes"] = {{{"mesh", 0}}};
  const int times = file.floats({0, 4}, "SCALAR"), moves = file.floats({0, 0, 0, 4, 0, 0}, "VEC3");
  json slow = one_channel_animation(0, "translation", times, moves), fast = slow;
  slow["name"] = "slow";
  fast["name"] = "fast";
  fast["samplers"][0]["input"] = file.floats({0, 1}, "SCALAR");
  file.gltf["animations"] = {slow, fast};
  const fs::path path = write("two.gltf", file.done());
  EXPECT_EQ(GltfAnimation::load(path).name(), "slow");
  const GltfAnimation chosen = GltfAnimation::load(path, "fast");
  EXPECT_EQ(chosen.name(), "fast");
  EXPECT_EQ(chosen.duration_s(), 1.0);
  expect_pose(chosen.node_pose_at(0, 0.5), SE3(identity3(), {2, 0, 0}));
}

// A triangle of one colour in its own frame (z up).
Mesh triangle_mesh(float red) {
  Mesh mesh;
  mesh.positions = {0, 0, 0, 0.2f, 0, 0, 0, 0.1f, 0.3f};
  mesh.normals = {0, -0.9486833f, 0.3162278f, 0, -0.9486833f, 0.3162278f, 0, -0.9486833f, 0.3162278f};
  mesh.indices = {0, 1, 2};
  mesh.parts = {MeshPart{0, 3, {red, 0.5f, 0.25f, 1}}};
  return mesh;
}

// The writer's animated nodes read back: at each key its pose, between keys SE3::interpolate of
// the two (within 1e-6 m and rad), including keys 170 and -170 degrees about z, whose plain
// quaternions disagree in sign (the short way is 20 degrees through 180, not 340).
TEST_F(GltfAnimationTest, WrittenAnimatedNodesReadBackAtAndBetweenTheKeys) {
  GlbAnimatedNode cart{"cart", triangle_mesh(0.1f), {}}, ball{"ball", triangle_mesh(0.9f), {}};
  cart.keys = {{0, SE3()},
               {0.5, object_pose(170, {0, 0, 1}, {1, 0, 0})},
               {1.5, object_pose(-170, {0, 0, 1}, {1, 2, 0})},
               {2, SE3::from_rt({0.3, -2.2, 0.5}, {0, 2, 1})},
               {2.25, SE3::from_rt({-1.0, 1.2, 2.5}, {-3, 0.5, 1.5})}};
  ball.keys = {{0.25, SE3::from_rt({1.5, 0, 0}, {0, 0, 1})}, {1, SE3::from_rt({0, 0.7, -2.9}, {0.5, 0.5, 0.5})}};
  GltfLight lamp;
  lamp.name = "lamp";
  lamp.type = "point";
  lamp.position = {1, 2, 3};
  const fs::path path = write_glb("scene.glb", encode_glb(triangle_mesh(0.5f), "test", {lamp}, {cart, ball}, "moves"));

  const GltfAnimation animation = GltfAnimation::load(path, "moves");
  EXPECT_EQ(animation.name(), "moves");
  EXPECT_NEAR(animation.duration_s(), 2.25, 1e-7);
  ASSERT_EQ(animation.lights_at(3).size(), 1u);
  EXPECT_LT(norm(animation.lights_at(3)[0].position - lamp.position), kTolerance);
  for (const GlbAnimatedNode* node : {&cart, &ball}) {
    SCOPED_TRACE(node->name);
    const int index = *animation.find_node(node->name);
    EXPECT_TRUE(animation.moves(index));
    for (const GlbAnimatedNode::Key& key : node->keys) expect_pose(animation.node_pose_at(index, key.t_s), key.T_world_node);
    expect_pose(animation.node_pose_at(index, -1), node->keys.front().T_world_node);
    expect_pose(animation.node_pose_at(index, 10), node->keys.back().T_world_node);
    for (size_t k = 0; k + 1 < node->keys.size(); ++k)
      for (double s : {0.1, 0.5, 0.77}) {
        SCOPED_TRACE(s);
        const GlbAnimatedNode::Key &a = node->keys[k], &b = node->keys[k + 1];
        expect_pose(animation.node_pose_at(index, a.t_s + s * (b.t_s - a.t_s)), a.T_world_node.interpolate(b.T_world_node, s));
      }
  }
  // Halfway between 170 and -170 degrees: 180, the short way.
  expect_pose(animation.node_pose_at(*animation.find_node("cart"), 1), object_pose(180, {0, 0, 1}, {1, 1, 0}));

  // The still part, the whole at rest (each node at its first key), and a node in its own frame.
  EXPECT_EQ(load_gltf_mesh(path, GltfMeshSelection{"", true}).triangle_count(), 1u);
  EXPECT_EQ(load_gltf_mesh(path).triangle_count(), 3u);
  const Mesh alone = load_gltf_mesh(path, GltfMeshSelection{"ball", false});
  ASSERT_EQ(alone.vertex_count(), 3u);
  for (size_t v = 0; v < 3; ++v) EXPECT_LT(norm(vertex(alone, v) - vertex(ball.mesh, v)), 1e-7);
  EXPECT_EQ(alone.parts.at(0).base_color, ball.mesh.parts[0].base_color);
}

// The written rotation keys as stored (glTF's x, y, z, w), read from the .glb's chunks: a reader
// whose slerp does not look for the short way still takes it when each key agrees in sign with the one
// before. The keys' input carries min and max, as glTF requires of animation inputs.
TEST_F(GltfAnimationTest, WrittenRotationKeysStayOnOneHemisphere) {
  GlbAnimatedNode spin{"spin", triangle_mesh(1), {}};
  for (int k = 0; k < 8; ++k) spin.keys.push_back({0.5 * k, object_pose(130 * k, {0, 0.6, 0.8}, {0, 0, 0})});
  const std::vector<uint8_t> glb = encode_glb(Mesh{}, "test", {}, {spin});
  uint32_t json_length = 0;
  std::memcpy(&json_length, glb.data() + 12, 4);
  const json gltf = json::parse(glb.begin() + 20, glb.begin() + 20 + json_length);
  const uint8_t* bin = glb.data() + 20 + json_length + 8;
  const json& animation = gltf["animations"][0];
  ASSERT_EQ(animation["channels"][1]["target"]["path"], "rotation");
  const json& input = gltf["accessors"][animation["samplers"][1]["input"].get<size_t>()];
  EXPECT_EQ(input["min"], json::array({0.0}));
  EXPECT_EQ(input["max"], json::array({3.5}));
  const json& output = gltf["accessors"][animation["samplers"][1]["output"].get<size_t>()];
  ASSERT_EQ(output["count"], 8);
  std::vector<float> q(32);
  std::memcpy(q.data(), bin + gltf["bufferViews"][output["bufferView"].get<size_t>()]["byteOffset"].get<size_t>(), 128);
  for (size_t k = 1; k < 8; ++k) {
    const double cosine = q[4 * k] * q[4 * k - 4] + q[4 * k + 1] * q[4 * k - 3] + q[4 * k + 2] * q[4 * k - 2] + q[4 * k + 3] * q[4 * k - 1];
    EXPECT_GT(cosine, 0) << "keys " << k - 1 << " and " << k;  // 130 degrees apart: cos(65) of the half angle
  }
}

TEST_F(GltfAnimationTest, AWrittenFileMayHoldOnlyAnimatedNodes) {
  GlbAnimatedNode marker{"marker", triangle_mesh(1), {{0, SE3()}, {1, object_pose(0, {0, 0, 1}, {1, 0, 0})}}};
  const fs::path path = write_glb("marker.glb", encode_glb(Mesh{}, "test", {}, {marker}));
  const GltfAnimation animation = GltfAnimation::load(path);
  EXPECT_EQ(animation.name(), "scene");
  expect_pose(animation.node_pose_at(*animation.find_node("marker"), 0.25), SE3(identity3(), {0.25, 0, 0}));
  EXPECT_EQ(load_gltf_mesh(path).triangle_count(), 1u);
}

TEST_F(GltfAnimationTest, TheWriterRefusesAnimatedNodesThatAreNotOne) {
  const GlbAnimatedNode good{"a", triangle_mesh(1), {{0, SE3()}, {1, SE3()}}};
  const auto refused = [&](const GlbAnimatedNode& bad, const std::string& part) {
    try {
      encode_glb(Mesh{}, "t", {}, {good, bad});
      ADD_FAILURE() << "no invalid_argument for " << part;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
    }
  };
  GlbAnimatedNode bad = good;
  bad.name = "b";
  bad.keys.clear();
  refused(bad, "no keys");
  bad.keys = {{1, SE3()}, {1, SE3()}};
  refused(bad, "not after key 0");
  bad.keys = {{-1, SE3()}};
  refused(bad, "key 0 at -1 s");
  bad.keys = {{NAN, SE3()}};
  refused(bad, "key 0");
  bad.keys = {{0, SE3(identity3(), {NAN, 0, 0})}};
  refused(bad, "not finite");
  bad = good;
  refused(bad, "the name of animated node 0");
  bad.name = "";
  refused(bad, "no name");
  bad = good;
  bad.name = "b";
  bad.mesh = Mesh{};
  refused(bad, "not a triangle mesh");
  EXPECT_THROW(encode_glb(Mesh{}, "t", {}, {}), std::invalid_argument);  // nothing at all
}

}  // namespace
}  // namespace arpipe
