// End-to-end: the default replay through the real arpiped with its cube made a rigid body and
// thrown (render.objects.0.physics): it flies along the throw, leaves a small world and is then
// removed and counted in every results line, and a second run gives the same positions bit for bit.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tests/e2e/child_process.h"

namespace fs = std::filesystem;
using namespace arpipe;

namespace {

std::vector<nlohmann::json> run_thrown_cube(const std::string& name) {
  const fs::path out = fs::path(ARPIPE_BINARY_DIR) / "e2e-out" / (name + "-" + std::to_string(getpid()));
  fs::remove_all(out);
  fs::create_directories(out);
  const std::vector<std::string> args{
      "--config", (fs::path(ARPIPE_SOURCE_DIR) / "configs/arpipe.toml").string(),
      "--set", "source.path=\"" + (fs::path(ARPIPE_BINARY_DIR) / "default-capture").string() + "\"",
      "--set", "sinks.png.enabled=false", "--set", "sinks.y4m.enabled=false",
      "--set", "sinks.results.path=\"" + (out / "results.jsonl").string() + "\"",
      "--set", "render.objects.0.physics.kind=\"dynamic\"",
      "--set", "render.objects.0.physics.velocity_mps=[3.0, 0.0, 1.0]",
      "--set", "render.physics.world_radius_m=0.4"};
  std::string stderr_text;
  EXPECT_EQ(test::run_to_exit(test::build_program("arpiped"), args, out / "logs", &stderr_text), 0) << stderr_text;
  std::vector<nlohmann::json> lines;
  std::ifstream in(out / "results.jsonl");
  for (std::string line; std::getline(in, line);) lines.push_back(nlohmann::json::parse(line));
  fs::remove_all(out);
  return lines;
}

TEST(PhysicsReplay, AThrownCubeFliesLeavesTheWorldAndIsCountedTheSameEveryRun) {
  const std::vector<nlohmann::json> first = run_thrown_cube("thrown-a"), second = run_thrown_cube("thrown-b");
  ASSERT_FALSE(first.empty());
  ASSERT_EQ(first.size(), second.size());
  double last_x = -1;
  bool removed = false;
  int drawn_with_physics = 0;
  for (size_t i = 0; i < first.size(); ++i) {
    if (!first[i].contains("objects")) continue;  // no pose: nothing drawn, nothing reported
    ASSERT_TRUE(first[i].contains("physics")) << first[i].dump();
    ++drawn_with_physics;
    const nlohmann::json& cube = first[i]["objects"][0];
    EXPECT_EQ(cube, second[i]["objects"][0]) << "frame " << i << ": the replay differs";
    if (cube["present"].get<bool>()) {
      // Thrown along +x: it only moves further (0.4 m from the origin it leaves the world).
      const double x = cube["position_m"][0].get<double>();
      EXPECT_GT(x, last_x) << "frame " << i;
      last_x = x;
      EXPECT_FALSE(removed) << "frame " << i << ": back after it was removed";
    } else {
      removed = true;
      EXPECT_EQ(first[i]["physics"]["removed"]["beyond_radius"], 1) << first[i].dump();
    }
  }
  EXPECT_GT(drawn_with_physics, 10);
  // 3 m/s along x from the origin: past 0.4 m in about 0.13 s, 4 frames.
  EXPECT_TRUE(removed);
}

}  // namespace
