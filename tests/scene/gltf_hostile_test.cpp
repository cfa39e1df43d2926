// The glTF loader against hostile files (issue 18, findings 1, 2, 3, 8 and 9): offsets near 2^64,
// buffers outside the asset's folder, FIFOs, node graphs that are not trees, counts far beyond the
// data, non-finite numbers; and animations (GltfAnimation, the node selection of load_gltf_mesh):
// indices out of range, counts past the limits, keys that are not times or not rotations. Each is an
// AssetError naming the file and the place, never a crash, a hang, a huge allocation or the bytes
// of a file the asset may not read.
#include <fcntl.h>
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "core/scene/asset_error.h"
#include "core/scene/gltf_animation.h"
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
    return error_of(path, [&] { load_gltf_mesh(path); });
  }
  std::string animation_error(const fs::path& path, std::string_view name = "") {
    return error_of(path, [&] { GltfAnimation::load(path, name); });
  }
  template <class Load>
  std::string error_of(const fs::path& path, Load load) {
    try {
      load();
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

// ---- Animations (gltf_document.cpp's checks, GltfAnimation::load, node_pose_at, selections) ----

// The triangle's node moved by one LINEAR translation channel with keys at 0 and 1 s: accessor 3
// the times, 4 the values.
render_test::AnimatedGltf moving_triangle(const std::vector<float>& times = {0, 1},
                                          const std::vector<float>& values = {0, 0, 0, 1, 0, 0}) {
  render_test::AnimatedGltf file;
  const int input = file.floats(times, "SCALAR"), output = file.floats(values, "VEC3");
  file.gltf["animations"] = {render_test::one_channel_animation(0, "translation", input, output)};
  return file;
}

TEST_F(GltfHostile, AnimationsThatAreNotAnArrayOfObjectsAreRefused) {
  json gltf = moving_triangle().done();
  gltf["animations"] = {{"channels", 1}};
  EXPECT_TRUE(contains(load_error(write_gltf("object.gltf", gltf)), "\"animations\" is not an array"));
  gltf["animations"] = {5};
  EXPECT_TRUE(contains(load_error(write_gltf("number.gltf", gltf)), "animation 0: not an object"));
  gltf["animations"] = {{{"channels", json::array()}, {"samplers", json::array()}, {"name", 5}}};
  EXPECT_TRUE(contains(load_error(write_gltf("name.gltf", gltf)), "animation 0: \"name\" must be a string"));
  gltf["animations"] = {{{"channels", json::array()}}};
  EXPECT_TRUE(contains(load_error(write_gltf("samplers.gltf", gltf)), "animation 0: \"samplers\" must be an array"));
  gltf["animations"] = {{{"samplers", json::array()}}};
  EXPECT_TRUE(contains(load_error(write_gltf("channels.gltf", gltf)), "animation 0: \"channels\" must be an array"));
}

TEST_F(GltfHostile, AnimationCountsPastTheLimitsAreRefused) {
  json gltf = moving_triangle().done();
  const json empty = {{"channels", json::array()}, {"samplers", json::array()}};
  gltf["animations"] = json::array();
  for (size_t a = 0; a <= kMaxGltfAnimations; ++a) gltf["animations"].push_back(empty);
  std::string message = load_error(write_gltf("animations.gltf", gltf));
  EXPECT_TRUE(contains(message, "\"animations\" has 4097 entries, over the limit of 4096")) << message;

  gltf = moving_triangle().done();
  json& animation = gltf["animations"][0];
  const json sampler = animation["samplers"][0], channel = animation["channels"][0];
  for (size_t i = 0; i < kMaxGltfAnimationSamplers; ++i) animation["samplers"].push_back(sampler);
  message = load_error(write_gltf("samplers.gltf", gltf));
  EXPECT_TRUE(contains(message, "animation 0: 65537 samplers, over the limit of 65536")) << message;
  animation["samplers"] = {sampler};
  for (size_t i = 0; i < kMaxGltfAnimationChannels; ++i) animation["channels"].push_back(channel);
  message = load_error(write_gltf("channels.gltf", gltf));
  EXPECT_TRUE(contains(message, "animation 0: 65537 channels, over the limit of 65536")) << message;
}

TEST_F(GltfHostile, AnimationSamplerIndicesOutOfRangeAreRefused) {
  for (const json& bad : {json(99), json(-1), json(1.5), json("3"), json(uint64_t{1} << 63)}) {
    SCOPED_TRACE(bad.dump());
    for (const char* key : {"input", "output"}) {
      json gltf = moving_triangle().done();
      gltf["animations"][0]["samplers"][0][key] = bad;
      const std::string message = load_error(write_gltf("sampler.gltf", gltf));
      EXPECT_TRUE(contains(message, fmt::format("animation 0 sampler 0: \"{}\" must be an accessor index below 5", key)))
          << message;
    }
    json gltf = moving_triangle().done();
    gltf["animations"][0]["channels"][0]["sampler"] = bad;
    std::string message = load_error(write_gltf("channel.gltf", gltf));
    EXPECT_TRUE(contains(message, "animation 0 channel 0: \"sampler\" must be an index below 1")) << message;
    gltf = moving_triangle().done();
    gltf["animations"][0]["channels"][0]["target"]["node"] = bad;
    message = load_error(write_gltf("node.gltf", gltf));
    EXPECT_TRUE(contains(message, "animation 0 channel 0: target \"node\" must be a node index below 1")) << message;
  }
}

TEST_F(GltfHostile, AnimationInterpolationAndPathOutsideGltfsAreRefused) {
  json gltf = moving_triangle().done();
  gltf["animations"][0]["samplers"][0]["interpolation"] = "SMOOTH";
  std::string message = load_error(write_gltf("interpolation.gltf", gltf));
  EXPECT_TRUE(contains(message, "animation 0 sampler 0: \"interpolation\" must be")) << message;
  gltf = moving_triangle().done();
  gltf["animations"][0]["channels"][0]["target"]["path"] = "pointer";
  message = load_error(write_gltf("path.gltf", gltf));
  EXPECT_TRUE(contains(message, "animation 0 channel 0: target \"path\" must be")) << message;
  gltf["animations"][0]["channels"][0]["target"] = 3;
  message = load_error(write_gltf("target.gltf", gltf));
  EXPECT_TRUE(contains(message, "animation 0 channel 0: \"target\" must be an object")) << message;
}

// glTF: a channel without a node (an extension's, such as KHR_animation_pointer) is ignored; the
// channels after it keep their numbers in messages. Extras and extensions are dropped.
TEST_F(GltfHostile, AnimationChannelWithoutANodeIsIgnoredAndTheNextKeepsItsNumber) {
  json gltf = moving_triangle().done();
  json& animation = gltf["animations"][0];
  animation["extras"] = {{"deep", {{"deeper", json::array({1, 2})}}}};
  animation["samplers"][0]["extensions"] = {{"EXT_unknown", {{"x", 1}}}};
  const json pointer = {{"sampler", 0},
                        {"target", {{"path", "pointer"}, {"extensions", {{"KHR_animation_pointer", {{"pointer", "/x"}}}}}}}};
  animation["channels"].insert(animation["channels"].begin(), pointer);
  const fs::path path = write_gltf("pointer.gltf", gltf);
  EXPECT_TRUE(GltfAnimation::load(path).moves(0));
  EXPECT_EQ(load_gltf_mesh(path).triangle_count(), 1u);
  animation["samplers"][0]["output"] = 3;  // the times: SCALAR, not VEC3
  const std::string message = animation_error(write_gltf("renumbered.gltf", gltf));
  EXPECT_TRUE(contains(message, "animation 0 channel 1 (sampler 0) output: accessor 3 must be VEC3 of FLOAT")) << message;
}

TEST_F(GltfHostile, AnimationInputThatIsNotTimesIsRefused) {
  json gltf = moving_triangle().done();
  gltf["accessors"][3]["type"] = "VEC2";
  std::string message = animation_error(write_gltf("vec2.gltf", gltf));
  EXPECT_TRUE(contains(message, "animation 0 sampler 0 input: accessor 3 must be SCALAR of FLOAT")) << message;
  gltf["accessors"][3]["type"] = "SCALAR";
  gltf["accessors"][3]["count"] = 0;
  message = animation_error(write_gltf("none.gltf", gltf));
  EXPECT_TRUE(contains(message, "animation 0 sampler 0 input: accessor 3 has no keys")) << message;
  message = animation_error(write_gltf("negative.gltf", moving_triangle({-1, 1}).done()));
  EXPECT_TRUE(contains(message, "animation 0 sampler 0 input: accessor 3 element 0 is -1 s, before 0")) << message;
  message = animation_error(write_gltf("repeated.gltf", moving_triangle({0, 1, 1}, {0, 0, 0, 1, 0, 0, 2, 0, 0}).done()));
  EXPECT_TRUE(contains(message, "animation 0 sampler 0 input: accessor 3 element 2 is 1 s, not after element 1")) << message;
  message = animation_error(write_gltf("nan.gltf", moving_triangle({0, NAN}).done()));
  EXPECT_TRUE(contains(message, "animation 0 sampler 0 input: accessor 3 element 1 is not finite")) << message;
}

TEST_F(GltfHostile, AnimationOutputOfAnotherCountOrTypeIsRefused) {
  std::string message = animation_error(write_gltf("count.gltf", moving_triangle({0, 1}, {0, 0, 0}).done()));
  EXPECT_TRUE(contains(message, "animation 0 channel 0 (sampler 0) output: accessor 4 has 1 elements, but the input's 2 keys need 2"))
      << message;
  json gltf = moving_triangle().done();
  gltf["animations"][0]["samplers"][0]["interpolation"] = "CUBICSPLINE";
  message = animation_error(write_gltf("cubic.gltf", gltf));
  EXPECT_TRUE(contains(message, "has 2 elements, but the input's 2 keys need 6")) << message;
  message = animation_error(write_gltf("inf.gltf", moving_triangle({0, 1}, {0, 0, 0, 1, INFINITY, 0}).done()));
  EXPECT_TRUE(contains(message, "animation 0 channel 0 (sampler 0) output: accessor 4 element 1 is not finite")) << message;
  gltf = moving_triangle().done();
  gltf["accessors"][4]["count"] = 1000;
  message = animation_error(write_gltf("past.gltf", gltf));
  EXPECT_TRUE(contains(message, "animation 0 channel 0 (sampler 0) output: accessor 4 (1000 elements")) << message;
  EXPECT_TRUE(contains(message, "does not fit")) << message;
}

TEST_F(GltfHostile, AnimationRotationsThatAreNotRotationsAreRefused) {
  render_test::AnimatedGltf file;
  const int times = file.floats({0, 1}, "SCALAR"), vec3 = file.floats({0, 0, 0, 1, 0, 0}, "VEC3");
  const int zero = file.floats({0, 0, 0, 1, 0, 0, 0, 0}, "VEC4");
  file.gltf["animations"] = {render_test::one_channel_animation(0, "rotation", times, vec3)};
  const std::string vec4 = "animation 0 channel 0 (sampler 0) output: accessor 4 must be VEC4 of FLOAT, or of normalized";
  std::string message = animation_error(write_gltf("vec3.gltf", file.done()));
  EXPECT_TRUE(contains(message, vec4)) << message;
  file.gltf["animations"][0]["samplers"][0]["output"] = zero;
  message = animation_error(write_gltf("zero.gltf", file.done()));
  EXPECT_TRUE(contains(message, "animation 0 channel 0 (sampler 0) output: accessor 5: the rotation of key 1 has zero length"))
      << message;
  // Integers must be normalized, floats must not; UNSIGNED_INT is not among glTF's types for them.
  json gltf = file.done();
  gltf["accessors"][5]["componentType"] = 5122;  // SHORT, not normalized
  message = animation_error(write_gltf("short.gltf", gltf));
  EXPECT_TRUE(contains(message, "accessor 5 must be VEC4 of FLOAT, or of normalized")) << message;
  gltf["accessors"][5]["componentType"] = 5125;
  gltf["accessors"][5]["normalized"] = true;
  message = animation_error(write_gltf("uint.gltf", gltf));
  EXPECT_TRUE(contains(message, "accessor 5 must be VEC4 of FLOAT, or of normalized")) << message;
}

TEST_F(GltfHostile, AnimationSamplerOrChannelThatIsNotAnObjectIsRefused) {
  json gltf = moving_triangle().done();
  gltf["animations"][0]["samplers"][0] = "s";
  EXPECT_TRUE(contains(load_error(write_gltf("sampler.gltf", gltf)), "animation 0 sampler 0: not an object"));
  gltf = moving_triangle().done();
  gltf["animations"][0]["channels"].push_back(json::array());
  EXPECT_TRUE(contains(load_error(write_gltf("channel.gltf", gltf)), "animation 0 channel 1: not an object"));
}

// A CUBICSPLINE rotation between q and -q with flat tangents passes through zero at halfway: no
// rotation there, an error naming the channel and the time.
TEST_F(GltfHostile, AnimationCubicRotationThroughZeroIsRefusedWhereItIsZero) {
  render_test::AnimatedGltf file;
  const std::vector<float> flat{0, 0, 0, 0};
  std::vector<float> keys = flat;
  for (const std::vector<float>& part : {std::vector<float>{0, 0, 0, 1}, flat, flat, std::vector<float>{0, 0, 0, -1}, flat})
    keys.insert(keys.end(), part.begin(), part.end());
  const int times = file.floats({0, 2}, "SCALAR"), turns = file.floats(keys, "VEC4");
  file.gltf["animations"] = {render_test::one_channel_animation(0, "rotation", times, turns, "CUBICSPLINE")};
  const fs::path path = write_gltf("zero.gltf", file.done());
  const GltfAnimation animation = GltfAnimation::load(path);
  animation.node_pose_at(0, 0.5);  // a quarter of the way: still a rotation
  const std::string message = error_of(path, [&] { animation.node_pose_at(0, 1); });
  EXPECT_TRUE(contains(message, "animation 0 channel 0 (sampler 0): the rotation at t = 1 s has length 0")) << message;
}

TEST_F(GltfHostile, AnimationKeysPastTheLimitAreRefused) {
  // A GLB whose BIN chunk holds kMaxGltfAnimationKeys + 1 increasing times.
  std::vector<float> times(kMaxGltfAnimationKeys + 1);
  for (size_t k = 0; k < times.size(); ++k) times[k] = float(k);
  std::vector<uint8_t> bin = render_test::triangle_buffer_bytes();
  bin.resize(80);
  render_test::append<float>(bin, times);
  json gltf = triangle_json();
  gltf["buffers"] = {{{"byteLength", bin.size()}}};
  gltf["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", 80}, {"byteLength", times.size() * 4}});
  gltf["accessors"].push_back({{"bufferView", 3}, {"componentType", 5126}, {"count", times.size()}, {"type", "SCALAR"}});
  gltf["animations"] = {render_test::one_channel_animation(0, "translation", 3, 0)};
  std::string message = animation_error(write("keys.glb", render_test::glb(gltf.dump(), bin)));
  EXPECT_TRUE(contains(message, "animation 0 sampler 0 input: accessor 3 has 1000001 elements, over the limit of 1000000 keys"))
      << message;

  // 17 samplers, each with an input of a million keys of its own (one bufferView): 17 million
  // elements, past the 16 million one load reads.
  gltf["accessors"][3]["count"] = kMaxGltfAnimationKeys;
  json samplers = json::array();
  for (int s = 0; s < 17; ++s) {
    gltf["accessors"].push_back(gltf["accessors"][3]);
    samplers.push_back({{"input", 4 + s}, {"output", 0}});
  }
  gltf["animations"] = {{{"channels", json::array()}, {"samplers", samplers}}};
  message = animation_error(write("budget.glb", render_test::glb(gltf.dump(), bin)));
  EXPECT_TRUE(contains(message, "animation 0 sampler 16 input: reading the animation reads more than 16000000 accessor elements"))
      << message;
}

TEST_F(GltfHostile, AnimationNameThatIsNoneOrTwoAnimationsIsRefused) {
  json gltf = moving_triangle().done();
  gltf["animations"][0]["name"] = "walk";
  std::string message = animation_error(write_gltf("walk.gltf", gltf), "run");
  EXPECT_TRUE(contains(message, "no animation is named \"run\" (the file's: \"walk\")")) << message;
  gltf["animations"].push_back(gltf["animations"][0]);
  message = animation_error(write_gltf("twice.gltf", gltf), "walk");
  EXPECT_TRUE(contains(message, "animations 0 and 1 are both named \"walk\"")) << message;
  message = animation_error(write_gltf("none.gltf", triangle_json()), "walk");
  EXPECT_TRUE(contains(message, "no animation is named \"walk\" (the file's: none)")) << message;
}

TEST_F(GltfHostile, AnimationOfAMatrixNodeOrOfOneTargetTwiceIsRefused) {
  json gltf = moving_triangle().done();
  gltf["nodes"][0] = {{"mesh", 0}, {"name", "fixed"}, {"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}}};
  std::string message = animation_error(write_gltf("matrix.gltf", gltf));
  EXPECT_TRUE(contains(message, "animation 0 channel 0: its target, node 0 (\"fixed\"), has a matrix")) << message;
  gltf = moving_triangle().done();
  gltf["animations"][0]["channels"].push_back(gltf["animations"][0]["channels"][0]);
  message = animation_error(write_gltf("twice.gltf", gltf));
  EXPECT_TRUE(contains(message, "animation 0 channel 1: node 0's translation is the target of channel 0 already")) << message;
}

// node_pose_at: a global transform that is not rigid times a uniform scale names the node.
TEST_F(GltfHostile, AnimatedPoseThatIsNotRigidNamesTheNode) {
  json gltf = moving_triangle().done();
  gltf["nodes"] = {{{"name", "squash"}, {"scale", {1, 2, 1}}, {"children", {1}}}, {{"name", "child"}, {"mesh", 0}}};
  const fs::path squashed = write_gltf("squash.gltf", gltf);
  const GltfAnimation at_rest = GltfAnimation::load(squashed);
  std::string message = error_of(squashed, [&] { at_rest.node_pose_at(1, 0); });
  EXPECT_TRUE(contains(message, "node 1 (\"child\"): its global transform at t = 0 s is not a rotation, a translation and a uniform scale"))
      << message;
  gltf["nodes"][0]["scale"] = {-1, 1, 1};
  const fs::path mirrored = write_gltf("mirror.gltf", gltf);
  message = error_of(mirrored, [&] { GltfAnimation::load(mirrored).node_pose_at(1, 0); });
  EXPECT_TRUE(contains(message, "mirrors")) << message;
  // Scale keys: uniform at t = 0, not at t = 1.
  render_test::AnimatedGltf keyed;
  const int times = keyed.floats({0, 1}, "SCALAR"), scales = keyed.floats({2, 2, 2, 1, 1, 3}, "VEC3");
  keyed.gltf["animations"] = {render_test::one_channel_animation(0, "scale", times, scales)};
  const fs::path path = write_gltf("keyed.gltf", keyed.done());
  const GltfAnimation animation = GltfAnimation::load(path);
  EXPECT_NEAR(animation.node_pose_at(0, 0).scale, 2.0, 1e-12);
  message = error_of(path, [&] { animation.node_pose_at(0, 1); });
  EXPECT_TRUE(contains(message, "node 0: its global transform at t = 1 s")) << message;
  message = error_of(path, [&] { animation.node_pose_at(3, 0); });
  EXPECT_TRUE(contains(message, "node 3 is not a node of the scene")) << message;
}

TEST_F(GltfHostile, NodeNameCarriedTwiceIsRefusedWhenChosen) {
  json gltf = triangle_json();
  gltf["nodes"] = {{{"name", "twin"}, {"mesh", 0}}, {{"name", "twin"}, {"mesh", 0}}};
  gltf["scenes"] = {{{"nodes", {0, 1}}}};
  const fs::path path = write_gltf("twins.gltf", gltf);
  const std::string message = error_of(path, [&] { load_gltf_mesh(path, GltfMeshSelection{"twin", false}); });
  EXPECT_TRUE(contains(message, "nodes 0 and 1 are both named \"twin\"")) << message;
  const GltfAnimation animation = GltfAnimation::load(path);
  EXPECT_TRUE(contains(error_of(path, [&] { animation.find_node("twin"); }), "nodes 0 and 1 are both named \"twin\""));
}

TEST_F(GltfHostile, NodeSelectionOfNoNodeOrOfNoTrianglesIsRefused) {
  json gltf = moving_triangle().done();
  gltf["nodes"] = {{{"name", "moving"}, {"mesh", 0}}, {{"name", "empty"}}};
  gltf["scenes"] = {{{"nodes", {0, 1}}}};
  const fs::path path = write_gltf("selection.gltf", gltf);
  std::string message = error_of(path, [&] { load_gltf_mesh(path, GltfMeshSelection{"absent", false}); });
  EXPECT_TRUE(contains(message, "no node of the scene is named \"absent\"")) << message;
  message = error_of(path, [&] { load_gltf_mesh(path, GltfMeshSelection{"empty", false}); });
  EXPECT_TRUE(contains(message, "contains no triangles")) << message;
  EXPECT_TRUE(contains(message, "in the subtree of node 1 (\"empty\")")) << message;
  message = error_of(path, [&] { load_gltf_mesh(path, GltfMeshSelection{"", true}); });
  EXPECT_TRUE(contains(message, "in the scene without the nodes its animations move")) << message;
}

TEST_F(GltfHostile, LoadedMeshRemembersItsFile) {
  const fs::path path = write_gltf("source.gltf", triangle_json());
  EXPECT_EQ(load_gltf_mesh(path).source, path.string());
}

}  // namespace
}  // namespace arpipe
