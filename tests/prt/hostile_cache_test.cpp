// The PRT cache file is untrusted (issue 18): a FIFO, a directory, a file over the size limit, a
// header claiming 2^60 vertices or a shape that does not fit the mesh is a cache miss with a
// reason, never a block, a crash or a huge allocation; and a bake's mesh error names the mesh's file.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

#include "core/scene/asset_error.h"
#include "core/scene/builtin_meshes.h"
#include "render/prt/prt_bake.h"
#include "render/prt/prt_cache.h"

namespace arpipe {
namespace {

namespace fs = std::filesystem;

class PrtHostileCache : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("arpipe-prt-hostile-test-" + std::to_string(::getpid()) + "-" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    settings_.samples_per_axis = 4;
    key_ = prt_cache_key(mesh_, settings_);
    file_ = prt_cache_file(dir_, key_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string read_bytes(const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }
  void write_bytes(const fs::path& file, const std::string& bytes) {
    std::ofstream(file, std::ios::binary | std::ios::trunc).write(bytes.data(), std::streamsize(bytes.size()));
  }
  // A valid cache file for mesh_ (baked once).
  std::string valid_bytes() {
    const PrtLoad load = load_or_bake_prt(mesh_, settings_, dir_);
    EXPECT_TRUE(load.baked);
    return read_bytes(load.file);
  }
  // read_prt_cache's miss reason (fails the test when it is a hit or throws).
  std::string miss_reason() {
    std::string why;
    EXPECT_FALSE(read_prt_cache(file_, key_, &why));
    return why;
  }

  fs::path dir_, file_;
  std::string key_;
  Mesh mesh_ = make_cube_mesh(0.06, 1);
  PrtBakeSettings settings_;
};

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

TEST_F(PrtHostileCache, FifoIsAMissWithoutBlocking) {
  ASSERT_EQ(::mkfifo(file_.c_str(), 0600), 0);
  const std::string why = miss_reason();
  EXPECT_TRUE(contains(why, "it is a FIFO (named pipe), expected a regular file")) << why;
  const PrtLoad load = load_or_bake_prt(mesh_, settings_, dir_);
  EXPECT_TRUE(load.baked);
}

TEST_F(PrtHostileCache, DirectoryIsAMiss) {
  fs::create_directories(file_);
  const std::string why = miss_reason();
  EXPECT_TRUE(contains(why, "it is a directory, expected a regular file")) << why;
}

TEST_F(PrtHostileCache, FileOverTheSizeLimitIsAMissWithoutReadingIt) {
  std::string bytes = valid_bytes();
  write_bytes(file_, bytes);
  fs::resize_file(file_, kMaxPrtCacheBytes + 1);  // sparse: nothing is written
  const auto start = std::chrono::steady_clock::now();
  const std::string why = miss_reason();
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(1));
  EXPECT_TRUE(contains(why, std::to_string(kMaxPrtCacheBytes))) << why;
}

TEST_F(PrtHostileCache, HeaderClaiming2To60VerticesIsAMiss) {
  std::string bytes = valid_bytes();
  for (int i = 0; i < 8; ++i) bytes[55 + size_t(i)] = i == 7 ? char(0x10) : char(0);  // V = 2^60
  write_bytes(file_, bytes);
  const std::string why = miss_reason();
  EXPECT_TRUE(contains(why, "truncated") || contains(why, "over the limit")) << why;
}

TEST_F(PrtHostileCache, ShapeThatDoesNotFitTheMeshIsAMissBeforeTheBodyIsRead) {
  write_bytes(file_, valid_bytes());
  std::string why;
  EXPECT_FALSE(read_prt_cache(file_, key_, &why, PrtCacheShape{mesh_.vertex_count() + 1, settings_.bands}));
  EXPECT_TRUE(contains(why, "does not fit the mesh")) << why;
  EXPECT_TRUE(read_prt_cache(file_, key_, &why, PrtCacheShape{mesh_.vertex_count(), settings_.bands})) << why;
}

TEST_F(PrtHostileCache, TruncatedToEachLengthIsAMissNeverACrash) {
  const std::string bytes = valid_bytes();
  for (size_t length : {size_t(0), size_t(5), size_t(11), size_t(50), size_t(66), size_t(67), size_t(74),
                        bytes.size() / 2, bytes.size() - 1}) {
    write_bytes(file_, bytes.substr(0, length));
    EXPECT_FALSE(miss_reason().empty()) << length;
  }
}

TEST_F(PrtHostileCache, SymlinkLoopIsAMiss) {
  fs::create_symlink(file_, file_);
  EXPECT_FALSE(miss_reason().empty());
}

// Finding 9: a bake's non-finite vertex named no file.
TEST(PrtBakeMessages, NonFiniteVertexNamesTheMeshFile) {
  Mesh mesh = make_cube_mesh(0.06, 1);
  mesh.source = "models/cup.gltf";
  mesh.positions[4] = std::numeric_limits<float>::quiet_NaN();
  try {
    validate_prt_mesh(mesh);
    ADD_FAILURE() << "no AssetError";
  } catch (const AssetError& e) {
    EXPECT_TRUE(contains(e.what(), "models/cup.gltf: ")) << e.what();
    EXPECT_TRUE(contains(e.what(), "vertex 1 has a non-finite position")) << e.what();
  }
}

TEST(PrtBakeMessages, BuiltinMeshErrorNamesTheBuiltin) {
  Mesh mesh = *make_builtin_mesh("builtin:cube");
  mesh.normals[0] = 0;
  mesh.normals[1] = 0;
  mesh.normals[2] = 0;
  try {
    validate_prt_mesh(mesh);
    ADD_FAILURE() << "no AssetError";
  } catch (const AssetError& e) {
    EXPECT_TRUE(contains(e.what(), "builtin:cube")) << e.what();
  }
}

}  // namespace
}  // namespace arpipe
