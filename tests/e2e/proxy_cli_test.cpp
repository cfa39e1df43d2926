// `arpipe proxy simplify` as a person runs it: a builtin sphere reduced 10:1 into a .glb that
// loads back, the table it prints, a camera model; bad input exits 1 or 2 naming the file or the
// option, and leaves no file behind nor an earlier result damaged.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "core/geometry/camera_model.h"
#include "core/scene/gltf_loader.h"
#include "tests/e2e/child_process.h"
#include "tests/scene/gltf_test_files.h"

namespace fs = std::filesystem;
using namespace arpipe;

namespace {

class ArpipeProxyCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(ARPIPE_BINARY_DIR) / "e2e-out" / ::testing::UnitTest::GetInstance()->current_test_info()->name();
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "out");
  }
  int run(const std::vector<std::string>& args, std::string* out = nullptr, std::string* err = nullptr) {
    test::ChildProcess child(test::build_program("arpipe"), args, dir_ / "logs");
    const int status = child.wait();
    if (out) *out = child.stdout_text();
    if (err) *err = child.stderr_text();
    if (status == -1 || !WIFEXITED(status)) return -1;  // a timeout or a crash
    return WEXITSTATUS(status);
  }
  std::vector<std::string> files_in(const fs::path& folder) {
    std::vector<std::string> names;
    for (const fs::directory_entry& entry : fs::directory_iterator(folder)) names.push_back(entry.path().filename().string());
    return names;
  }
  // A tetrahedron (4 triangles) as a .gltf with its buffer embedded; `poison` replaces the x of
  // its third vertex (NaN: a hostile file).
  fs::path write_tetrahedron(const std::string& name, float poison = 0) {
    std::vector<uint8_t> bytes;
    render_test::append<float>(bytes, {0, 0, 0, 1, 0, 0, poison, 1, 0, 0, 0, 1});
    render_test::append<uint16_t>(bytes, {0, 2, 1, 0, 1, 3, 1, 2, 3, 0, 3, 2});
    const std::string json = R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
      "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
      "buffers": [{"byteLength": 72, "uri": "data:application/octet-stream;base64,)" + render_test::base64(bytes) + R"("}],
      "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 24}],
      "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 1]},
                    {"bufferView": 1, "componentType": 5123, "count": 12, "type": "SCALAR"}]})";
    const fs::path path = dir_ / name;
    std::ofstream(path) << json;
    return path;
  }
  fs::path dir_;
};

TEST_F(ArpipeProxyCli, SimplifiesABuiltinSphereTenToOneIntoAGlbThatLoadsBack) {
  const fs::path out = dir_ / "out" / "sphere.glb";
  std::string text, err;
  ASSERT_EQ(run({"proxy", "simplify", "builtin:sphere", "--ratio", "10", "--out", out.string()}, &text, &err), 0) << err;
  // builtin:sphere has 24 rings: 2 * 24 * 2 * 23 = 2208 triangles, at most 220 left.
  EXPECT_NE(text.find("  original              2208"), std::string::npos) << text;
  EXPECT_NE(text.find("  welded                2208       1106  yes"), std::string::npos) << text;  // seam and poles
  EXPECT_NE(text.find("  simplified             220        660  yes"), std::string::npos) << text;
  EXPECT_NE(text.find("ratio            10.04:1"), std::string::npos) << text;
  EXPECT_NE(text.find("none given (--camera): a 640x480 pinhole with a 60 degree horizontal field of view"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("silhouette edge  error mean"), std::string::npos) << text;
  EXPECT_NE(text.find("over 26 views"), std::string::npos) << text;
  const Mesh loaded = load_gltf_mesh(out);
  EXPECT_EQ(loaded.triangle_count(), 220u);
  EXPECT_EQ(files_in(dir_ / "out"), std::vector<std::string>{"sphere.glb"});  // no temporary left

  // Again through a camera model with distortion, every view printed; the result replaced.
  const fs::path camera = dir_ / "opencv8.cameramodel";
  CameraModel("LENSMODEL_OPENCV8", {500, 510, 320, 240, -0.1, 0.01, 1e-4, -1e-4, 1e-3, 0, 0, 0}, 640, 480).save(camera);
  ASSERT_EQ(run({"proxy", "simplify", "builtin:sphere", "--ratio", "20", "--camera", camera.string(), "--per-view",
                 "--normals", "smooth", "--out", out.string()},
                &text, &err),
            0)
      << err;
  EXPECT_NE(text.find("LENSMODEL_OPENCV8, 640x480"), std::string::npos) << text;
  EXPECT_NE(text.find("  +x+y+z "), std::string::npos) << text;
  EXPECT_NE(text.find("smooth (per vertex, area-weighted)"), std::string::npos) << text;
  EXPECT_EQ(load_gltf_mesh(out).triangle_count(), 110u);

  // One view through --pose: the mesh 0.3 m in front of the camera.
  ASSERT_EQ(run({"proxy", "simplify", "builtin:cube", "--ratio", "64", "--pose", "0.3,0.2,0,0,0,0.3", "--out", out.string()},
                &text, &err),
            0)
      << err;
  EXPECT_NE(text.find("  simplified              12"), std::string::npos) << text;
  EXPECT_NE(text.find("over 1 view\n"), std::string::npos) << text;
}

TEST_F(ArpipeProxyCli, BadInputExitsNamingTheFileOrOptionAndLeavesTheOutputAlone) {
  const fs::path out = dir_ / "out" / "proxy.glb";
  std::ofstream(out) << "an earlier result";
  auto expect_untouched = [&](const std::string& what) {
    EXPECT_EQ(test::read_text(out), "an earlier result") << what;
    EXPECT_EQ(files_in(dir_ / "out"), std::vector<std::string>{"proxy.glb"}) << what;
  };
  std::string err;
  const std::string missing = (dir_ / "missing.glb").string();
  EXPECT_EQ(run({"proxy", "simplify", missing, "--out", out.string()}, nullptr, &err), 1);
  EXPECT_NE(err.find(missing), std::string::npos) << err;
  expect_untouched("missing input");

  const fs::path nan = write_tetrahedron("nan.gltf", std::numeric_limits<float>::quiet_NaN());
  EXPECT_EQ(run({"proxy", "simplify", nan.string(), "--out", out.string()}, nullptr, &err), 1);
  EXPECT_NE(err.find("nan.gltf"), std::string::npos) << err;
  expect_untouched("NaN position");

  const fs::path empty = dir_ / "empty.glb";
  std::ofstream(empty).flush();
  EXPECT_EQ(run({"proxy", "simplify", empty.string(), "--out", out.string()}, nullptr, &err), 1);
  EXPECT_NE(err.find("empty.glb"), std::string::npos) << err;
  expect_untouched("empty file");

  // 4 triangles cannot be reduced 10:1 and stay a solid.
  const fs::path tetrahedron = write_tetrahedron("tetrahedron.gltf");
  EXPECT_EQ(run({"proxy", "simplify", tetrahedron.string(), "--out", out.string()}, nullptr, &err), 1);
  EXPECT_NE(err.find("tetrahedron.gltf: ratio 10 leaves 0 of 4 triangles"), std::string::npos) << err;
  expect_untouched("ratio too large for the mesh");

  for (const char* ratio : {"1", "0.5", "-2", "nan", "inf", "1e12", "ten"}) {
    EXPECT_EQ(run({"proxy", "simplify", "builtin:cube", "--ratio", ratio, "--out", out.string()}, nullptr, &err), 2) << ratio;
    EXPECT_NE(err.find("arpipe proxy simplify: --ratio"), std::string::npos) << err;
  }
  EXPECT_EQ(run({"proxy", "simplify", "builtin:cube", "--out", (dir_ / "out" / "proxy.gltf").string()}, nullptr, &err), 2);
  EXPECT_NE(err.find("--out"), std::string::npos) << err;
  EXPECT_EQ(run({"proxy", "simplify", "builtin:cube", "--out", (dir_ / "nowhere" / "proxy.glb").string()}, nullptr, &err), 1);
  EXPECT_NE(err.find("nowhere"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(dir_ / "nowhere"));
  fs::create_directories(dir_ / "folder.glb");
  EXPECT_EQ(run({"proxy", "simplify", "builtin:cube", "--out", (dir_ / "folder.glb").string()}, nullptr, &err), 1);
  EXPECT_NE(err.find("folder.glb: it is a folder"), std::string::npos) << err;
  EXPECT_EQ(run({"proxy", "simplify", "builtin:cube", "--camera", (dir_ / "no.cameramodel").string(), "--out", out.string()},
                nullptr, &err),
            1);
  EXPECT_NE(err.find("no.cameramodel"), std::string::npos) << err;
  EXPECT_EQ(run({"proxy", "simplify", "builtin:cube", "--pose", "0,0,0,0,0,-1", "--out", out.string()}, nullptr, &err), 1);
  EXPECT_NE(err.find("no silhouette edge"), std::string::npos) << err;
  EXPECT_EQ(run({"proxy", "simplify", "builtin:cube", "--pose", "1,2,3", "--out", out.string()}, nullptr, &err), 2);
  EXPECT_NE(err.find("--pose"), std::string::npos) << err;
  EXPECT_EQ(run({"proxy", "simplify", "builtin:cube", "--view-distance-m", "0.01", "--out", out.string()}, nullptr, &err), 2);
  EXPECT_NE(err.find("bounding sphere"), std::string::npos) << err;
  EXPECT_EQ(run({"proxy", "simplify", "builtin:teapot", "--out", out.string()}, nullptr, &err), 1);
  EXPECT_NE(err.find("builtin:teapot"), std::string::npos) << err;
  EXPECT_EQ(run({"proxy"}, nullptr, &err), 2);  // no subcommand
  expect_untouched("usage errors");
}

TEST_F(ArpipeProxyCli, HelpNamesTheCommand) {
  std::string text, err;
  ASSERT_EQ(run({"--help"}, &text, &err), 0) << err;
  EXPECT_NE(text.find("  proxy "), std::string::npos) << text;
  ASSERT_EQ(run({"proxy", "simplify", "--help"}, &text, &err), 0) << err;
  EXPECT_NE(text.find("Usage: arpipe proxy simplify"), std::string::npos) << text;
  EXPECT_NE(text.find("--view-distance-m"), std::string::npos) << text;
}

}  // namespace
