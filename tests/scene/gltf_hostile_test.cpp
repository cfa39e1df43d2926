// The glTF loader against hostile files (issue 18, findings 1, 2, 3, 8 and 9): offsets near 2^64,
// buffers outside the asset's folder, FIFOs, node graphs that are not trees, counts far beyond the
// data, non-finite numbers. Each is an AssetError naming the file and the place, never a crash, a
// hang, a huge allocation or the bytes of a file the asset may not read.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "core/scene/asset_error.h"
#include "core/scene/gltf_limits.h"
#include "core/scene/gltf_loader.h"
#include "tests/scene/gltf_hostile_files.h"

namespace arpipe {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using render_test::triangle_json;
using render_test::write_file;

class GltfHostile : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(ARPIPE_BINARY_DIR) / "test_tmp" / "gltf_hostile" /
           ::testing::UnitTest::GetInstance()->current_test_info()->name();
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "asset");
  }
  fs::path write(const std::string& name, const std::string& bytes) {
    const fs::path path = dir_ / "asset" / name;
    write_file(path, bytes);
    return path;
  }
  fs::path write_gltf(const std::string& name, const json& gltf) { return write(name, gltf.dump()); }
  // The AssetError's message; fails the test when the load succeeds or throws anything else.
  std::string load_error(const fs::path& path) {
    try {
      load_gltf_mesh(path);
    } catch (const AssetError& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(path.string()), std::string::npos) << "the message names the file: " << message;
      EXPECT_EQ(message.find("max_size"), std::string::npos) << message;
      EXPECT_EQ(message.find("bad_alloc"), std::string::npos) << message;
      return message;
    } catch (const std::exception& e) {
      ADD_FAILURE() << "not an AssetError: " << e.what();
      return {};
    }
    ADD_FAILURE() << "no AssetError for " << path;
    return {};
  }
  fs::path dir_;
};

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// Finding 1: byteOffset + stride * (count - 1) + size wrapped past 2^64 to a small number, and the
// read started 8 bytes before the buffer.
TEST_F(GltfHostile, AccessorByteOffsetNear2To64IsRefusedNotWrapped) {
  json gltf = triangle_json();
  gltf["accessors"][0]["byteOffset"] = std::numeric_limits<uint64_t>::max() - 7;
  const std::string message = load_error(write_gltf("offset.gltf", gltf));
  EXPECT_TRUE(contains(message, "mesh 0 primitive 0 POSITION: accessor 0")) << message;
  EXPECT_TRUE(contains(message, "bufferView 0")) << message;
}

TEST_F(GltfHostile, BufferViewByteOffsetNear2To64IsRefused) {
  json gltf = triangle_json();
  gltf["bufferViews"][0]["byteOffset"] = std::numeric_limits<uint64_t>::max() - 3;
  const std::string message = load_error(write_gltf("view_offset.gltf", gltf));
  EXPECT_TRUE(contains(message, "bufferView 0")) << message;
}

// Finding 1 and 9: stride * (count - 1) wrapped to 0, the bounds check passed and the index vector
// of 2^62 elements failed with "cannot create std::vector larger than max_size()".
TEST_F(GltfHostile, AccessorCountTimesStrideWrappingIsRefused) {
  json gltf = triangle_json();
  gltf["accessors"][2]["componentType"] = 5125;  // UNSIGNED_INT: stride 4, 4 * 2^62 wraps to 0
  gltf["accessors"][2]["count"] = (uint64_t{1} << 62) + 1;
  const std::string message = load_error(write_gltf("count_wrap.gltf", gltf));
  EXPECT_TRUE(contains(message, "mesh 0 primitive 0 indices: accessor 2")) << message;
}

// Finding 8: the vector of accessor.count positions was made before the bounds check.
TEST_F(GltfHostile, HugeAccessorCountIsRefusedBeforeAnyAllocation) {
  json gltf = triangle_json();
  gltf["accessors"][0]["count"] = uint64_t{1} << 40;
  const std::string message = load_error(write_gltf("huge_count.gltf", gltf));
  EXPECT_TRUE(contains(message, "accessor 0")) << message;
}

TEST_F(GltfHostile, StrideShorterThanTheElementIsRefused) {
  json gltf = triangle_json();
  gltf["bufferViews"][0]["byteStride"] = 4;  // VEC3 of FLOAT needs 12
  const std::string message = load_error(write_gltf("stride.gltf", gltf));
  EXPECT_TRUE(contains(message, "accessor 0")) << message;
  EXPECT_TRUE(contains(message, "stride")) << message;
}

// Finding 2: a buffer URI climbing out of the asset's folder was opened, and its bytes showed up
// in the message (as vertex indices).
TEST_F(GltfHostile, BufferUriOutsideTheAssetFolderIsNotOpened) {
  const std::string secret(78, 'S');
  fs::create_directories(dir_ / "private");
  write_file(dir_ / "private" / "secret.bin", secret);
  json gltf = triangle_json();
  gltf["buffers"][0]["uri"] = "../private/secret.bin";
  const std::string message = load_error(write_gltf("escape.gltf", gltf));
  EXPECT_TRUE(contains(message, "buffer 0")) << message;
  EXPECT_TRUE(contains(message, "outside")) << message;
  EXPECT_FALSE(contains(message, "SSSS")) << message;
  EXPECT_FALSE(contains(message, "1397969747")) << message;  // "SSSS" read as a uint32 index
}

TEST_F(GltfHostile, BufferUriNamingEtcPasswdIsNotOpened) {
  std::error_code error;
  const uintmax_t size = fs::file_size("/etc/passwd", error);
  if (error) GTEST_SKIP() << "no /etc/passwd";
  json gltf = triangle_json();
  gltf["buffers"][0]["uri"] = "../../../../../../../../../../../../etc/passwd";
  gltf["buffers"][0]["byteLength"] = size;
  gltf["bufferViews"][2]["byteLength"] = size - 72;
  gltf["accessors"][2]["componentType"] = 5125;
  gltf["accessors"][2]["count"] = 3;
  const std::string message = load_error(write_gltf("passwd.gltf", gltf));
  EXPECT_TRUE(contains(message, "outside")) << message;
  EXPECT_FALSE(contains(message, "root")) << message;
  EXPECT_FALSE(contains(message, "past the last vertex")) << message;
}

TEST_F(GltfHostile, SymlinkInsideTheFolderPointingOutsideIsNotFollowed) {
  fs::create_directories(dir_ / "private");
  write_file(dir_ / "private" / "secret.bin", std::string(78, 'S'));
  fs::create_symlink(dir_ / "private" / "secret.bin", dir_ / "asset" / "link.bin");
  json gltf = triangle_json();
  gltf["buffers"][0]["uri"] = "link.bin";
  const std::string message = load_error(write_gltf("symlink.gltf", gltf));
  EXPECT_TRUE(contains(message, "outside")) << message;
}

TEST_F(GltfHostile, SymlinkLoopIsAnAssetErrorWithoutFilesystemErrorText) {
  fs::create_symlink("loop_b.bin", dir_ / "asset" / "loop_a.bin");
  fs::create_symlink("loop_a.bin", dir_ / "asset" / "loop_b.bin");
  json gltf = triangle_json();
  gltf["buffers"][0]["uri"] = "loop_a.bin";
  const std::string message = load_error(write_gltf("loop.gltf", gltf));
  EXPECT_TRUE(contains(message, "buffer 0")) << message;
  EXPECT_FALSE(contains(message, "filesystem error")) << message;
}

TEST_F(GltfHostile, BufferUriNamingAFifoIsRefusedWithoutBlocking) {
  ASSERT_EQ(::mkfifo((dir_ / "asset" / "pipe.bin").c_str(), 0600), 0);
  json gltf = triangle_json();
  gltf["buffers"][0]["uri"] = "pipe.bin";
  const std::string message = load_error(write_gltf("fifo.gltf", gltf));
  EXPECT_TRUE(contains(message, "not a regular file")) << message;
}

TEST_F(GltfHostile, BufferUriNamingADeviceThroughASymlinkIsRefused) {
  fs::create_symlink("/dev/zero", dir_ / "asset" / "zero.bin");
  json gltf = triangle_json();
  gltf["buffers"][0]["uri"] = "zero.bin";
  load_error(write_gltf("device.gltf", gltf));
}

TEST_F(GltfHostile, GltfFileThatIsAFifoIsRefusedWithoutBlocking) {
  const fs::path path = dir_ / "asset" / "model.gltf";
  ASSERT_EQ(::mkfifo(path.c_str(), 0600), 0);
  EXPECT_TRUE(contains(load_error(path), "it is a FIFO (named pipe), expected a regular file"));
}

TEST_F(GltfHostile, ExternalBufferInsideTheFolderLoads) {
  const std::vector<uint8_t> bytes = render_test::triangle_buffer_bytes();
  fs::create_directories(dir_ / "asset" / "data");
  write_file(dir_ / "asset" / "data" / "triangle mesh.bin", std::string(bytes.begin(), bytes.end()));
  json gltf = triangle_json();
  gltf["buffers"][0]["uri"] = "data/../data/triangle%20mesh.bin";
  const Mesh mesh = load_gltf_mesh(write_gltf("external.gltf", gltf));
  EXPECT_EQ(mesh.vertex_count(), 3u);
  EXPECT_EQ(mesh.triangle_count(), 1u);
}

TEST_F(GltfHostile, ExternalBufferOfAnotherLengthIsRefused) {
  fs::create_directories(dir_ / "asset");
  write_file(dir_ / "asset" / "short.bin", std::string(40, '\0'));
  json gltf = triangle_json();
  gltf["buffers"][0]["uri"] = "short.bin";
  const std::string message = load_error(write_gltf("short.gltf", gltf));
  EXPECT_TRUE(contains(message, "buffer 0")) << message;
  EXPECT_TRUE(contains(message, "78")) << message;
}

TEST_F(GltfHostile, DeclaredBufferBytesOverTheLimitAreRefusedWithTheLimit) {
  json gltf = triangle_json();
  gltf["buffers"][0]["byteLength"] = uint64_t{1} << 40;
  const std::string message = load_error(write_gltf("big_buffer.gltf", gltf));
  EXPECT_TRUE(contains(message, std::to_string(kMaxGltfBufferBytes))) << message;
}

// Finding 3: add_node recursed once per level and overflowed the stack at 300k levels.
TEST_F(GltfHostile, DeepNodeChainIsRefusedWithTheDepthLimitNotAStackOverflow) {
  json gltf = triangle_json();
  render_test::make_node_chain(gltf, 300'000);
  const std::string message = load_error(write_gltf("deep.gltf", gltf));
  EXPECT_TRUE(contains(message, "depth")) << message;
  EXPECT_TRUE(contains(message, std::to_string(kMaxGltfNodeDepth))) << message;
}

TEST_F(GltfHostile, NodeChainWithinTheDepthLimitLoads) {
  json gltf = triangle_json();
  render_test::make_node_chain(gltf, kMaxGltfNodeDepth);
  const Mesh mesh = load_gltf_mesh(write_gltf("chain.gltf", gltf));
  EXPECT_EQ(mesh.triangle_count(), 1u);
}

// Finding 3: a node listing the same child twice, 24 levels deep, expanded to 2^24 copies.
TEST_F(GltfHostile, NodeReachedTwiceIsRefused) {
  json gltf = triangle_json();
  gltf["nodes"] = {{{"children", {1, 1}}}, {{"mesh", 0}}};
  gltf["scenes"] = {{{"nodes", {0}}}};
  const std::string message = load_error(write_gltf("twice.gltf", gltf));
  EXPECT_TRUE(contains(message, "node 1")) << message;
  EXPECT_TRUE(contains(message, "more than one parent")) << message;
}

TEST_F(GltfHostile, DoublingGraph24LevelsDeepIsRefusedAtOnce) {
  json gltf = triangle_json();
  json nodes = json::array();
  for (int i = 0; i < 24; ++i) nodes.push_back({{"children", {i + 1, i + 1}}});
  nodes.push_back({{"mesh", 0}});
  gltf["nodes"] = nodes;
  gltf["scenes"] = {{{"nodes", {0}}}};
  const auto start = std::chrono::steady_clock::now();
  const std::string message = load_error(write_gltf("doubling.gltf", gltf));
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(2));
  EXPECT_TRUE(contains(message, "more than one parent")) << message;
}

TEST_F(GltfHostile, SceneRootThatIsAlsoAChildIsRefused) {
  json gltf = triangle_json();
  gltf["nodes"] = {{{"children", {1}}}, {{"mesh", 0}}};
  gltf["scenes"] = {{{"nodes", {0, 1}}}};
  const std::string message = load_error(write_gltf("root_child.gltf", gltf));
  EXPECT_TRUE(contains(message, "node 1")) << message;
}

TEST_F(GltfHostile, NodeCycleIsRefused) {
  json gltf = triangle_json();
  gltf["nodes"] = {{{"children", {1}}, {"mesh", 0}}, {{"children", {0}}}};
  gltf["scenes"] = {{{"nodes", {0}}}};
  const std::string message = load_error(write_gltf("cycle.gltf", gltf));
  EXPECT_TRUE(contains(message, "node 0")) << message;
}

// Many nodes instancing one mesh of 9000 (degenerate) triangles: past the triangle limit.
TEST_F(GltfHostile, InstancesPastTheTriangleLimitAreRefusedWithTheLimit) {
  std::vector<uint8_t> bytes;
  render_test::append<float>(bytes, {0, 0, 0, 0, 0, 1});  // one vertex and its normal
  bytes.resize(bytes.size() + 27'000, 0);                   // 27000 UNSIGNED_BYTE indices, all 0
  json gltf = triangle_json();
  gltf["buffers"] = {{{"byteLength", bytes.size()}, {"uri", render_test::data_uri(bytes)}}};
  gltf["bufferViews"] = {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 12}},
                         {{"buffer", 0}, {"byteOffset", 12}, {"byteLength", 12}},
                         {{"buffer", 0}, {"byteOffset", 24}, {"byteLength", 27'000}}};
  gltf["accessors"] = {{{"bufferView", 0}, {"componentType", 5126}, {"count", 1}, {"type", "VEC3"}},
                       {{"bufferView", 1}, {"componentType", 5126}, {"count", 1}, {"type", "VEC3"}},
                       {{"bufferView", 2}, {"componentType", 5121}, {"count", 27'000}, {"type", "SCALAR"}}};
  json nodes = json::array();
  json children = json::array();
  for (int i = 1; i <= 500; ++i) {
    children.push_back(i);
  }
  nodes.push_back({{"children", children}});
  for (int i = 1; i <= 500; ++i) nodes.push_back({{"mesh", 0}});
  gltf["nodes"] = nodes;
  gltf["scenes"] = {{{"nodes", {0}}}};
  const std::string message = load_error(write_gltf("instances.gltf", gltf));
  EXPECT_TRUE(contains(message, "triangles")) << message;
  EXPECT_TRUE(contains(message, std::to_string(kMaxGltfTriangles))) << message;
}

// Finding 9: non-finite numbers are refused at load time with the accessor or node.
TEST_F(GltfHostile, NonFinitePositionNamesTheAccessorAndElement) {
  std::vector<uint8_t> bytes = render_test::triangle_buffer_bytes();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(bytes.data() + 12 + 4, &nan, 4);  // vertex 1's y
  json gltf = triangle_json();
  gltf["buffers"][0]["uri"] = render_test::data_uri(bytes);
  const std::string message = load_error(write_gltf("nan_position.gltf", gltf));
  EXPECT_TRUE(contains(message, "accessor 0")) << message;
  EXPECT_TRUE(contains(message, "element 1")) << message;
  EXPECT_TRUE(contains(message, "not finite")) << message;
}

TEST_F(GltfHostile, NonFiniteNormalNamesTheAccessor) {
  std::vector<uint8_t> bytes = render_test::triangle_buffer_bytes();
  const float inf = std::numeric_limits<float>::infinity();
  std::memcpy(bytes.data() + 36 + 24, &inf, 4);  // normal 2's x
  json gltf = triangle_json();
  gltf["buffers"][0]["uri"] = render_test::data_uri(bytes);
  const std::string message = load_error(write_gltf("inf_normal.gltf", gltf));
  EXPECT_TRUE(contains(message, "accessor 1")) << message;
  EXPECT_TRUE(contains(message, "element 2")) << message;
}

TEST_F(GltfHostile, TransformOverflowingToInfinityNamesTheNode) {
  json gltf = triangle_json();
  gltf["nodes"] = {{{"children", {1}}, {"scale", {1e200, 1e200, 1e200}}},
                   {{"mesh", 0}, {"scale", {1e200, 1e200, 1e200}}}};
  gltf["scenes"] = {{{"nodes", {0}}}};
  const std::string message = load_error(write_gltf("overflow.gltf", gltf));
  EXPECT_TRUE(contains(message, "node 1")) << message;
  EXPECT_TRUE(contains(message, "finite")) << message;
}

TEST_F(GltfHostile, VertexBeyondFloatRangeNamesTheNode) {
  json gltf = triangle_json();
  gltf["nodes"][0] = {{"mesh", 0}, {"scale", {1e39, 1e39, 1e39}}};  // finite in double, not in float
  const std::string message = load_error(write_gltf("float_range.gltf", gltf));
  EXPECT_TRUE(contains(message, "node 0")) << message;
  EXPECT_TRUE(contains(message, "float")) << message;
}

TEST_F(GltfHostile, DeeplyNestedExtrasAreRefusedWithTheDepthLimit) {
  std::string nested(200'000, '[');
  nested += std::string(200'000, ']');
  std::string text = triangle_json().dump();
  text.insert(text.size() - 1, ", \"extras\": " + nested);
  const std::string message = load_error(write("nested.gltf", text));
  EXPECT_TRUE(contains(message, "nest")) << message;
  EXPECT_TRUE(contains(message, std::to_string(kMaxGltfJsonDepth))) << message;
}

TEST_F(GltfHostile, JsonFileOverTheLimitIsRefusedBeforeReading) {
  const fs::path path = write("sparse.gltf", "{");
  fs::resize_file(path, kMaxGltfJsonBytes + 1);  // sparse: nothing is written
  const std::string message = load_error(path);
  EXPECT_TRUE(contains(message, std::to_string(kMaxGltfJsonBytes))) << message;
}

TEST_F(GltfHostile, GlbLoads) {
  const Mesh mesh = load_gltf_mesh(write("triangle.glb", render_test::triangle_glb()));
  EXPECT_EQ(mesh.vertex_count(), 3u);
  EXPECT_EQ(mesh.triangle_count(), 1u);
}

// tinygltf 2.7 lets a BIN chunk run 8 bytes past the end of the file.
TEST_F(GltfHostile, GlbBinChunkRunningPastTheFileIsRefused) {
  const std::string message = load_error(write("overrun.glb", render_test::triangle_glb(8)));
  EXPECT_TRUE(contains(message, "BIN chunk")) << message;
}

TEST_F(GltfHostile, GlbJsonChunkLongerThanTheFileIsRefused) {
  std::string bytes = render_test::triangle_glb();
  bytes[12] = '\xff';
  bytes[13] = '\xff';
  const std::string message = load_error(write("json_chunk.glb", bytes));
  EXPECT_TRUE(contains(message, "JSON chunk")) << message;
}

TEST_F(GltfHostile, LoadedMeshRemembersItsFile) {
  const fs::path path = write_gltf("source.gltf", triangle_json());
  EXPECT_EQ(load_gltf_mesh(path).source, path.string());
}

}  // namespace
}  // namespace arpipe
