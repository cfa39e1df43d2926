// The glTF seed corpus (tests/scene/corpus/, also the seeds of the glTF fuzz target): every
// valid_* file loads, every bad_* file (the crafted files of gltf_hostile_test.cpp, small enough
// for git) is an AssetError naming the file. Other files there (valid_external.bin) are data.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "core/scene/asset_error.h"
#include "core/scene/gltf_loader.h"

namespace arpipe {
namespace {

namespace fs = std::filesystem;

TEST(GltfCorpus, ValidFilesLoadAndBadFilesAreAssetErrorsNamingTheFile) {
  const fs::path corpus = fs::path(ARPIPE_SOURCE_DIR) / "tests" / "scene" / "corpus";
  int valid = 0, bad = 0;
  for (const fs::directory_entry& entry : fs::directory_iterator(corpus)) {
    const fs::path& path = entry.path();
    const std::string name = path.filename().string();
    if (path.extension() != ".gltf" && path.extension() != ".glb") continue;
    if (name.rfind("valid_", 0) == 0) {
      ++valid;
      try {
        const Mesh mesh = load_gltf_mesh(path);
        EXPECT_GT(mesh.triangle_count(), 0u) << name;
      } catch (const std::exception& e) {
        ADD_FAILURE() << name << ": " << e.what();
      }
    } else {
      ++bad;
      try {
        load_gltf_mesh(path);
        ADD_FAILURE() << name << " loaded";
      } catch (const AssetError& e) {
        EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
      } catch (const std::exception& e) {
        ADD_FAILURE() << name << ": not an AssetError: " << e.what();
      }
    }
  }
  EXPECT_GE(valid, 4);
  EXPECT_GE(bad, 10);
}

}  // namespace
}  // namespace arpipe
