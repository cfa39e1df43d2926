// The PRT cache: keyed by the mesh's content, loaded without a bake when up to date, and any
// damaged, foreign or stale file rejected with a reason and baked again; writes are atomic.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <functional>
#include <fstream>
#include <string>

#include "core/scene/builtin_meshes.h"
#include "render/prt/prt_bake.h"
#include "render/prt/prt_cache.h"

namespace arpipe {
namespace {

namespace fs = std::filesystem;

class PrtCache : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("arpipe-prt-cache-test-" + std::to_string(::getpid()) + "-" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    settings_.samples_per_axis = 6;  // the cache does not care about quality: a fast bake
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string read_bytes(const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }
  void write_bytes(const fs::path& file, const std::string& bytes) {
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), std::streamsize(bytes.size()));
  }
  // Bakes into the cache, damages the file, and checks that the next load rejects it (saying
  // `reason`) and bakes again, repairing the file.
  void expect_rejected(const std::function<void(std::string&)>& damage, const std::string& reason) {
    const PrtLoad first = load_or_bake_prt(mesh_, settings_, dir_);
    ASSERT_TRUE(first.baked);
    std::string bytes = read_bytes(first.file);
    damage(bytes);
    write_bytes(first.file, bytes);
    std::string why;
    EXPECT_FALSE(read_prt_cache(first.file, prt_cache_key(mesh_, settings_), &why));
    EXPECT_NE(why.find(reason), std::string::npos) << why;
    const PrtLoad again = load_or_bake_prt(mesh_, settings_, dir_);
    EXPECT_TRUE(again.baked);
    EXPECT_NE(again.note.find(reason), std::string::npos) << again.note;
    EXPECT_EQ(again.transfer.coefficients, first.transfer.coefficients);
    EXPECT_FALSE(load_or_bake_prt(mesh_, settings_, dir_).baked) << "the re-bake repaired the cache";
  }

  fs::path dir_;
  Mesh mesh_ = make_cube_mesh(0.06, 2);
  PrtBakeSettings settings_;
};

TEST_F(PrtCache, KeyIs32HexCharsAndFollowsTheContent) {
  const std::string key = prt_cache_key(mesh_, settings_);
  ASSERT_EQ(key.size(), 32u);
  EXPECT_EQ(key.find_first_not_of("0123456789abcdef"), std::string::npos);
  EXPECT_EQ(prt_cache_key(mesh_, settings_), key);
  Mesh moved = mesh_;
  moved.positions[7] += 1e-6f;
  EXPECT_NE(prt_cache_key(moved, settings_), key);
  PrtBakeSettings other = settings_;
  other.samples_per_axis += 1;
  EXPECT_NE(prt_cache_key(mesh_, other), key);
  other = settings_;
  other.kind = TransferKind::Unshadowed;
  EXPECT_NE(prt_cache_key(mesh_, other), key);
  other = settings_;
  other.seed = 2;
  EXPECT_NE(prt_cache_key(mesh_, other), key);
  other = settings_;
  other.threads = 7;  // the result does not depend on it
  EXPECT_EQ(prt_cache_key(mesh_, other), key);
  // Base colours matter only to the interreflected transfer.
  Mesh red = mesh_;
  red.set_base_color({1, 0, 0, 1});
  EXPECT_EQ(prt_cache_key(red, settings_), key);
  other = settings_;
  other.kind = TransferKind::Interreflected;
  EXPECT_NE(prt_cache_key(red, other), prt_cache_key(mesh_, other));
  EXPECT_EQ(prt_cache_file("/c", key), fs::path("/c/" + key + ".prt"));
}

TEST_F(PrtCache, UnchangedMeshLoadsWithoutBakingAndAMovedVertexBakesAgain) {
  const PrtLoad first = load_or_bake_prt(mesh_, settings_, dir_);
  EXPECT_TRUE(first.baked);
  EXPECT_TRUE(fs::exists(first.file));
  EXPECT_EQ(first.file, prt_cache_file(dir_, prt_cache_key(mesh_, settings_)));
  const PrtLoad second = load_or_bake_prt(mesh_, settings_, dir_);
  EXPECT_FALSE(second.baked);
  EXPECT_EQ(second.transfer.coefficients, first.transfer.coefficients);
  EXPECT_EQ(second.transfer.bands, first.transfer.bands);
  EXPECT_EQ(second.transfer.kind, first.transfer.kind);
  EXPECT_EQ(second.transfer.samples_per_axis, settings_.samples_per_axis);
  Mesh moved = mesh_;
  moved.positions[0] += 0.001f;
  const PrtLoad third = load_or_bake_prt(moved, settings_, dir_);
  EXPECT_TRUE(third.baked);
  EXPECT_NE(third.file, first.file);
}

TEST_F(PrtCache, WriteLeavesNoTemporaryFiles) {
  const PrtLoad load = load_or_bake_prt(mesh_, settings_, dir_);
  write_prt_cache(load.file, prt_cache_key(mesh_, settings_), load.transfer);  // over an existing file
  size_t files = 0;
  for (const auto& entry : fs::directory_iterator(dir_)) {
    ++files;
    EXPECT_EQ(entry.path().extension(), ".prt") << entry.path();
  }
  EXPECT_EQ(files, 1u);
  // A write that fails at the rename (a directory holds the final name) removes its temp file.
  fs::create_directories(dir_ / "taken.prt");
  EXPECT_THROW(write_prt_cache(dir_ / "taken.prt", prt_cache_key(mesh_, settings_), load.transfer), std::runtime_error);
  files = 0;
  for (const auto& entry : fs::directory_iterator(dir_)) {
    ++files;
    EXPECT_EQ(entry.path().extension(), ".prt") << entry.path();
  }
  EXPECT_EQ(files, 2u);
}

TEST_F(PrtCache, TruncatedFileIsRebaked) {
  expect_rejected([](std::string& b) { b.resize(b.size() - 5); }, "truncated");
}

TEST_F(PrtCache, TruncatedHeaderIsRebaked) {
  expect_rejected([](std::string& b) { b.resize(30); }, "truncated");
}

TEST_F(PrtCache, FlippedByteIsRebaked) {
  expect_rejected([](std::string& b) { b[b.size() / 2] = char(b[b.size() / 2] ^ 0x10); }, "corrupt");
}

TEST_F(PrtCache, OtherVersionIsRebaked) {
  expect_rejected([](std::string& b) { b[11] = char(kPrtCacheVersion + 1); }, "format version 2");
}

TEST_F(PrtCache, FileOfAnotherKeyIsRebaked) {
  // A valid file written for another key, under this key's name.
  const std::string key = prt_cache_key(mesh_, settings_);
  PrtBakeSettings other = settings_;
  other.seed = 99;
  const std::string other_key = prt_cache_key(mesh_, other);
  write_prt_cache(prt_cache_file(dir_, key), other_key, bake_prt(mesh_, other));
  std::string why;
  EXPECT_FALSE(read_prt_cache(prt_cache_file(dir_, key), key, &why));
  EXPECT_NE(why.find("holds key " + other_key), std::string::npos) << why;
  const PrtLoad load = load_or_bake_prt(mesh_, settings_, dir_);
  EXPECT_TRUE(load.baked);
  EXPECT_NE(load.note.find("holds key"), std::string::npos) << load.note;
}

TEST_F(PrtCache, NotACacheFileAndMissingFileAreReasons) {
  std::string why;
  EXPECT_FALSE(read_prt_cache(dir_ / "none.prt", "x", &why));
  EXPECT_NE(why.find("no cache file"), std::string::npos) << why;
  fs::create_directories(dir_);
  write_bytes(dir_ / "junk.prt", "hello");
  EXPECT_FALSE(read_prt_cache(dir_ / "junk.prt", "x", &why));
  EXPECT_NE(why.find("not a PRT cache file"), std::string::npos) << why;
}

TEST_F(PrtCache, UnwritableCacheDirStillReturnsTheTransferWithANote) {
  // A cache "directory" below a regular file cannot be created, whoever runs the test.
  fs::create_directories(dir_);
  write_bytes(dir_ / "a-file", "x");
  const PrtLoad load = load_or_bake_prt(mesh_, settings_, dir_ / "a-file" / "prt");
  EXPECT_TRUE(load.baked);
  EXPECT_EQ(load.transfer.vertex_count(), mesh_.vertex_count());
  EXPECT_NE(load.note.find("not cached"), std::string::npos) << load.note;
  EXPECT_THROW(write_prt_cache(dir_ / "a-file" / "prt" / "k.prt", prt_cache_key(mesh_, settings_), load.transfer),
               std::runtime_error);
}

TEST_F(PrtCache, NoCacheDirBakesWithANote) {
  const PrtLoad load = load_or_bake_prt(mesh_, settings_, {});
  EXPECT_TRUE(load.baked);
  EXPECT_TRUE(load.file.empty());
  EXPECT_FALSE(load.note.empty());
}

TEST_F(PrtCache, DefaultDirFollowsXdgThenHome) {
  const char* xdg = std::getenv("XDG_CACHE_HOME");
  const char* home = std::getenv("HOME");
  const std::string saved_xdg = xdg ? xdg : "", saved_home = home ? home : "";
  ::setenv("XDG_CACHE_HOME", "/x/cache", 1);
  EXPECT_EQ(default_prt_cache_dir(), fs::path("/x/cache/arpipe/prt"));
  ::unsetenv("XDG_CACHE_HOME");
  ::setenv("HOME", "/home/u", 1);
  EXPECT_EQ(default_prt_cache_dir(), fs::path("/home/u/.cache/arpipe/prt"));
  ::unsetenv("HOME");
  EXPECT_TRUE(default_prt_cache_dir().empty());
  if (xdg) ::setenv("XDG_CACHE_HOME", saved_xdg.c_str(), 1);
  if (home) ::setenv("HOME", saved_home.c_str(), 1);
}

}  // namespace
}  // namespace arpipe
