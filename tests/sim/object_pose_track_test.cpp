// Objects with a pose track ([[object.keyframe]]): the loader reads the keys and names the file,
// the object and the key in each error; object_pose_at holds the keys, interpolates between them
// as glTF's LINEAR channels do (checked against hand-made interpolations) and clamps outside them;
// scene_at_time places every object.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "capture/sim/sim_scene_loader.h"

namespace arpipe::sim {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;
constexpr double kExact = 1e-12;

SimScene parse(const std::string& text) { return parse_sim_scene(text, "scene.toml", {}); }

std::string error_of(const std::string& text) {
  try {
    parse(text);
  } catch (const SceneError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no SceneError for:\n" << text;
  return "";
}

// The message starts with the file and line, names the dotted key and says `also` (the object's
// name, or what was wrong).
void expect_error(const std::string& text, int line, const std::string& key, const std::string& also) {
  const std::string message = error_of(text);
  EXPECT_EQ(message.rfind("scene.toml:" + std::to_string(line) + ":", 0), 0u) << message;
  EXPECT_NE(message.find(" " + key + ": "), std::string::npos) << "key " << key << " not in: " << message;
  EXPECT_NE(message.find(also), std::string::npos) << "'" << also << "' not in: " << message;
}

void expect_pose_near(const SE3& actual, const SE3& expected, double tolerance) {
  for (size_t i = 0; i < 3; ++i) EXPECT_NEAR(actual.translation()[i], expected.translation()[i], tolerance) << i;
  EXPECT_LE(rotation_angle_between(actual, expected), tolerance);
}

SE3 yaw_at(double yaw_deg, const Vec3& position) { return SE3::from_rt({0, 0, yaw_deg * kDeg}, position); }

// A cart with three keys: from (0.2, 0.1) to (-0.2, 0.1) turning 90 degrees, then back up.
constexpr const char* kCart = R"([[object]]
name = "cart"
shape = "mesh"
mesh = "builtin:box"
size_m = [0.1, 0.1, 0.1]
position = [0.2, 0.1, 0.0]
[[object.keyframe]]
time_s = 0.0
position = [0.2, 0.1, 0.0]
rotation_deg = [0, 0, 0]
[[object.keyframe]]
time_s = 1.0
position = [-0.2, 0.1, 0.0]
rotation_deg = [0, 0, 90]
[[object.keyframe]]
time_s = 1.5
position = [-0.2, 0.3, 0.05]

[[object]]
name = "table"
)";

// ---- The loader ----------------------------------------------------------------------------------

TEST(ObjectPoseTrack, KeysLoadWithTheirTimesAndPoses) {
  const SimScene scene = parse(kCart);
  const SimObject& cart = scene.objects[0];
  ASSERT_EQ(cart.keyframes.size(), 3u);
  EXPECT_EQ(cart.keyframes[0].time_s, 0.0);
  EXPECT_EQ(cart.keyframes[1].time_s, 1.0);
  EXPECT_EQ(cart.keyframes[2].time_s, 1.5);
  expect_pose_near(cart.keyframes[0].T_world_object, yaw_at(0, {0.2, 0.1, 0}), kExact);
  expect_pose_near(cart.keyframes[1].T_world_object, yaw_at(90, {-0.2, 0.1, 0}), kExact);
  // A key's rotation defaults to the object's own (none here), not to the previous key's.
  expect_pose_near(cart.keyframes[2].T_world_object, yaw_at(0, {-0.2, 0.3, 0.05}), kExact);
  expect_pose_near(cart.T_world_object, cart.keyframes[0].T_world_object, 0);
  EXPECT_TRUE(scene.has_animated_objects());
  EXPECT_TRUE(scene.objects[1].keyframes.empty());
}

TEST(ObjectPoseTrack, WithoutItsOwnPoseAnAnimatedObjectRestsAtItsFirstKey) {
  const SimScene scene = parse(
      "[[object]]\nshape = \"sphere\"\n"
      "[[object.keyframe]]\ntime_s = 0.25\nposition = [1, 2, 3]\nrotation_deg = [0, 0, 45]\n"
      "[[object.keyframe]]\ntime_s = 0.5\n");
  const SimObject& ball = scene.objects[0];
  expect_pose_near(ball.T_world_object, yaw_at(45, {1, 2, 3}), kExact);
  // A key without position or rotation takes the object's defaults.
  expect_pose_near(ball.keyframes[1].T_world_object, SE3(), 0);
}

TEST(ObjectPoseTrack, AVirtualObjectMayMoveToo) {
  const SimScene scene = parse("[[object]]\nvirtual = true\n[[object.keyframe]]\ntime_s = 0\n[[object.keyframe]]\ntime_s = 1\n");
  EXPECT_TRUE(scene.objects[0].is_virtual);
  EXPECT_EQ(scene.objects[0].keyframes.size(), 2u);
  EXPECT_TRUE(scene.has_animated_objects());
  EXPECT_FALSE(parse("[[object]]\n").has_animated_objects());
}

TEST(ObjectPoseTrack, BadKeysNameTheFileTheObjectAndTheKey) {
  const std::string head = "[[object]]\nname = \"cart\"\n";
  // A key without a time (line 3: the key's table).
  expect_error(head + "[[object.keyframe]]\nposition = [0, 0, 0]\n", 3, "object[0].keyframe[0].time_s", "\"cart\"");
  // Negative, not finite, not a number.
  expect_error(head + "[[object.keyframe]]\ntime_s = -0.5\n", 4, "object[0].keyframe[0].time_s", ">= 0");
  expect_error(head + "[[object.keyframe]]\ntime_s = nan\n", 4, "object[0].keyframe[0].time_s", "a finite number");
  expect_error(head + "[[object.keyframe]]\ntime_s = inf\n", 4, "object[0].keyframe[0].time_s", "a finite number");
  expect_error(head + "[[object.keyframe]]\ntime_s = \"soon\"\n", 4, "object[0].keyframe[0].time_s", "number");
  // Not strictly increasing: equal, then smaller.
  expect_error(head + "[[object.keyframe]]\ntime_s = 0.5\n[[object.keyframe]]\ntime_s = 0.5\n", 6,
               "object[0].keyframe[1].time_s", "object \"cart\": times must strictly increase");
  expect_error(head + "[[object.keyframe]]\ntime_s = 1\n[[object.keyframe]]\ntime_s = 2\n[[object.keyframe]]\ntime_s = 1.5\n",
               8, "object[0].keyframe[2].time_s", "strictly increase");
  // A key of another table's kind, or a key that is not a table.
  expect_error(head + "[[object.keyframe]]\ntime_s = 0\nlook_at = [0, 0, 0]\n", 5, "object[0].keyframe[0].look_at",
               "unknown key");
  expect_error(head + "keyframe = 3\n", 3, "object[0].keyframe", "an array of tables");
  // Half a turn or more between two keys: the short way is not defined.
  expect_error(head + "[[object.keyframe]]\ntime_s = 0\n[[object.keyframe]]\ntime_s = 1\nrotation_deg = [0, 0, 179.5]\n", 7,
               "object[0].keyframe[1].rotation_deg", "a turn of at most 179 degrees");
  // The object's own pose, given, must be the first key's (it would be ignored otherwise).
  expect_error(head + "position = [1, 0, 0]\n[[object.keyframe]]\ntime_s = 0\nposition = [2, 0, 0]\n", 3,
               "object[0].position", "the first keyframe's position [2, 0, 0]");
  expect_error(head + "rotation_deg = [0, 0, 10]\n[[object.keyframe]]\ntime_s = 0\nrotation_deg = [0, 0, 20]\n", 3,
               "object[0].rotation_deg", "the first keyframe's rotation (10 degrees from this one)");
  // A second object names its own index.
  expect_error("[[object]]\n" + head + "[[object.keyframe]]\ntime_s = -1\n", 5, "object[1].keyframe[0].time_s", ">= 0");
}

TEST(ObjectPoseTrack, AtMost10000KeysAnObject) {
  std::string text = "[[object]]\nname = \"busy\"\n";
  for (int k = 0; k <= 10000; ++k) text += "[[object.keyframe]]\ntime_s = " + std::to_string(k) + "\n";
  expect_error(text, 3, "object[0].keyframe", "at most 10000");
  // 10000 load.
  text = "[[object]]\n";
  for (int k = 0; k < 10000; ++k) text += "[[object.keyframe]]\ntime_s = " + std::to_string(k) + "\n";
  EXPECT_EQ(parse(text).objects[0].keyframes.size(), 10000u);
}

// ---- object_pose_at -----------------------------------------------------------------------------

SimObject object_with_keys(std::vector<SimPoseKey> keys) {
  SimObject object;
  object.keyframes = std::move(keys);
  if (!object.keyframes.empty()) object.T_world_object = object.keyframes.front().T_world_object;
  return object;
}

TEST(ObjectPoseTrack, WithoutKeysTheObjectStandsStill) {
  SimObject object;
  object.T_world_object = yaw_at(30, {1, 2, 3});
  for (double t : {-1.0, 0.0, 0.5, 1e9}) expect_pose_near(object_pose_at(object, t), object.T_world_object, 0);
}

TEST(ObjectPoseTrack, AtEachKeyItsPoseExactly) {
  const SimScene scene = parse(kCart);
  const SimObject& cart = scene.objects[0];
  for (const SimPoseKey& key : cart.keyframes) {
    const SE3 pose = object_pose_at(cart, key.time_s);
    EXPECT_EQ(pose.translation(), key.T_world_object.translation()) << key.time_s;
    EXPECT_EQ(pose.rotation(), key.T_world_object.rotation()) << key.time_s;
  }
}

TEST(ObjectPoseTrack, BetweenKeysTranslationIsLinearAndRotationTheSlerp) {
  // Pure translation: the midpoint, and a quarter of the way.
  const SimObject slide = object_with_keys({{1.0, yaw_at(0, {0, 0, 0})}, {3.0, yaw_at(0, {0.4, -0.2, 0.1})}});
  expect_pose_near(object_pose_at(slide, 2.0), yaw_at(0, {0.2, -0.1, 0.05}), kExact);
  expect_pose_near(object_pose_at(slide, 1.5), yaw_at(0, {0.1, -0.05, 0.025}), kExact);
  // A 90-degree turn about z: 45 degrees at the midpoint, 22.5 at a quarter (constant speed).
  const SimObject turn = object_with_keys({{0.0, yaw_at(0, {0, 0, 0})}, {1.0, yaw_at(90, {0, 0, 0})}});
  expect_pose_near(object_pose_at(turn, 0.5), yaw_at(45, {0, 0, 0}), kExact);
  expect_pose_near(object_pose_at(turn, 0.25), yaw_at(22.5, {0, 0, 0}), kExact);
  // Both at once, about an axis that is not z: each part on its own.
  const Vec3 axis = normalized(Vec3{1, 2, 2});
  const SimObject both = object_with_keys({{0.0, SE3::from_rt({0, 0, 0}, {1, 1, 1})},
                                           {2.0, SE3::from_rt((60 * kDeg) * axis, {3, 1, -1})}});
  expect_pose_near(object_pose_at(both, 1.0), SE3::from_rt((30 * kDeg) * axis, {2, 1, 0}), kExact);
  // The short way: from +170 to -170 degrees (20 degrees apart) passes through 180, not through 0.
  const SimObject wrap = object_with_keys({{0.0, yaw_at(170, {0, 0, 0})}, {1.0, yaw_at(-170, {0, 0, 0})}});
  expect_pose_near(object_pose_at(wrap, 0.5), yaw_at(180, {0, 0, 0}), 1e-9);
  expect_pose_near(object_pose_at(wrap, 0.25), yaw_at(175, {0, 0, 0}), 1e-9);
}

TEST(ObjectPoseTrack, EachSpanBetweenItsOwnTwoKeys) {
  const SimScene scene = parse(kCart);
  const SimObject& cart = scene.objects[0];
  // Halfway between keys 1 (t = 1, (-0.2, 0.1, 0), yaw 90) and 2 (t = 1.5, (-0.2, 0.3, 0.05), yaw 0).
  expect_pose_near(object_pose_at(cart, 1.25), yaw_at(45, {-0.2, 0.2, 0.025}), kExact);
  // Just before key 1: nearly there.
  expect_pose_near(object_pose_at(cart, 1.0 - 1e-9), cart.keyframes[1].T_world_object, 1e-8);
}

TEST(ObjectPoseTrack, OutsideItsKeysTheEndKeysHold) {
  const SimObject late = object_with_keys({{0.5, yaw_at(10, {1, 0, 0})}, {1.0, yaw_at(20, {2, 0, 0})}});
  for (double t : {-5.0, 0.0, 0.4999, std::numeric_limits<double>::quiet_NaN()})
    expect_pose_near(object_pose_at(late, t), late.keyframes.front().T_world_object, 0);
  for (double t : {1.0, 1.0001, 1e9, std::numeric_limits<double>::infinity()})
    expect_pose_near(object_pose_at(late, t), late.keyframes.back().T_world_object, 0);
  // One key: a still object wherever it is asked.
  const SimObject one = object_with_keys({{3.0, yaw_at(5, {0, 1, 0})}});
  for (double t : {0.0, 3.0, 9.0}) expect_pose_near(object_pose_at(one, t), one.keyframes[0].T_world_object, 0);
}

// ---- scene_at_time ------------------------------------------------------------------------------

TEST(ObjectPoseTrack, SceneAtTimePlacesEveryObjectAndStandsStill) {
  const SimScene scene = parse(kCart);
  const SimScene still = scene_at_time(scene, 0.5);
  ASSERT_EQ(still.objects.size(), scene.objects.size());
  EXPECT_FALSE(still.has_animated_objects());
  expect_pose_near(still.objects[0].T_world_object, yaw_at(45, {0, 0.1, 0}), kExact);
  expect_pose_near(still.objects[1].T_world_object, scene.objects[1].T_world_object, 0);
  EXPECT_EQ(still.objects[0].name, "cart");
  // Everything else as it was.
  EXPECT_EQ(still.objects[0].mesh_builtin, "builtin:box");
  EXPECT_EQ(still.camera.fps, scene.camera.fps);
}

}  // namespace
}  // namespace arpipe::sim
