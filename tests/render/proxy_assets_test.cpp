// Hostile proxy meshes and sizes: a missing file, a file with no triangles, a NaN vertex, a mesh
// that is not manifold where it must collide, and a sized builtin without a size each give an
// error naming the config key and the file (or the value), before anything is drawn.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "core/config/config.h"
#include "core/scene/builtin_meshes.h"
#include "core/scene/glb_writer.h"
#include "render/scene_physics.h"
#include "render/uploaded_objects.h"

namespace arpipe {
namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::path(ARPIPE_BINARY_DIR) / "proxy-assets-test";
  fs::create_directories(dir);
  return dir / name;
}

void write_bytes(const fs::path& path, const std::vector<uint8_t>& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

Config one_proxy(const std::string& mesh) {
  Config config;
  SceneProxy proxy;
  proxy.mesh = mesh;
  config.render.proxies = {proxy};
  return config;
}

// The message of whatever load_object_meshes throws (empty when it throws nothing).
std::string load_error(const Config& config) {
  try {
    load_object_meshes(config);
  } catch (const std::exception& e) {
    return e.what();
  }
  return {};
}

void expect_fragments(const std::string& message, const std::vector<std::string>& fragments) {
  EXPECT_FALSE(message.empty());
  for (const std::string& f : fragments) EXPECT_NE(message.find(f), std::string::npos) << "'" << f << "' missing from: " << message;
}

TEST(ProxyAssets, AMissingFileIsNamedWithItsKey) {
  const fs::path missing = scratch("no-such-proxy.glb");
  fs::remove(missing);
  expect_fragments(load_error(one_proxy(missing.string())), {"render.proxies[0].mesh", missing.string()});
  Config collision = one_proxy("builtin:box");
  collision.render.proxies[0].collision_mesh = missing.string();
  expect_fragments(load_error(collision), {"render.proxies[0].collision_mesh", missing.string()});
}

TEST(ProxyAssets, AFileWithoutTrianglesIsRefused) {
  const fs::path empty = scratch("empty.gltf");
  std::ofstream(empty) << R"({"asset": {"version": "2.0"}, "scenes": [{"nodes": []}], "scene": 0})";
  expect_fragments(load_error(one_proxy(empty.string())), {"render.proxies[0].mesh", empty.string()});
}

// A .glb whose first position is made NaN after writing (the writer refuses NaN itself).
TEST(ProxyAssets, ANanVertexIsRefused) {
  Mesh mesh = make_box_mesh({0.1, 0.1, 0.1}, 1);
  mesh.positions[0] = 0.0123f;  // a value to find in the binary chunk
  std::vector<uint8_t> bytes = encode_glb(mesh, "test");
  float marker = 0.0123f;
  uint8_t pattern[4];
  std::memcpy(pattern, &marker, 4);
  bool patched = false;
  for (size_t i = 0; i + 4 <= bytes.size() && !patched; ++i)
    if (std::memcmp(bytes.data() + i, pattern, 4) == 0) {
      const float nan = std::numeric_limits<float>::quiet_NaN();
      std::memcpy(bytes.data() + i, &nan, 4);
      patched = true;
    }
  ASSERT_TRUE(patched);
  const fs::path path = scratch("nan.glb");
  write_bytes(path, bytes);
  expect_fragments(load_error(one_proxy(path.string())), {"render.proxies[0].mesh", path.string()});
}

// Three triangles on one edge (a book of three pages): drawn it may be, collided as triangles not.
TEST(ProxyAssets, ANonManifoldCollisionMeshIsRefusedNamingTheProxy) {
  Mesh book;
  book.positions = {0, 0, 0, 0.1f, 0, 0, 0.05f, 0.05f, 0, 0.05f, -0.05f, 0, 0.05f, 0, 0.05f};
  book.normals = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 1, 0};
  book.indices = {0, 1, 2, 1, 0, 3, 0, 1, 4};
  book.parts = {MeshPart{0, 9, {1, 1, 1, 1}}};
  const fs::path path = scratch("book.glb");
  write_bytes(path, encode_glb(book, "test"));
  Config config = one_proxy(path.string());
  config.render.proxies[0].name = "shelf";
  config.render.proxies[0].collider = ColliderChoice::Triangles;
  SceneObject ball;
  ball.mesh = "builtin:sphere";
  ball.prt = ObjectPrt::Off;
  ball.physics.kind = ObjectMotion::Dynamic;
  config.render.objects = {ball};
  const LoadedMeshes meshes = load_object_meshes(config);  // drawing it is fine
  try {
    ScenePhysics physics(config, meshes);
    ADD_FAILURE() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    expect_fragments(e.what(), {"render.proxies[0]", "shelf", "not manifold"});
  }
}

TEST(ProxyAssets, ASizedBuiltinNeedsTheSizesItUses) {
  Config box = one_proxy("builtin:box");
  box.render.proxies[0].size_m = {0.1, 0.1, 0.0};
  expect_fragments(load_error(box), {"render.proxies[0].size_m[2]", "above 0"});
  Config plane = one_proxy("builtin:plane");
  plane.render.proxies[0].size_m = {0.5, 0.4, 0.0};  // a plane has no height
  EXPECT_EQ(load_error(plane), "");
}

}  // namespace
}  // namespace arpipe
