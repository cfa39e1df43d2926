// Reproducers the fuzz targets found in the HDR readers (tests/fuzz/regressions): each is a clean
// AssetError naming the file, before the OpenEXR library allocates from a header it trusts.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "core/image/openexr_file.h"
#include "core/scene/asset_error.h"

namespace arpipe {
namespace {

namespace fs = std::filesystem;

TEST(HdrFuzzRegressions, AnExrHeaderWithoutItsRequiredAttributesIsRefused) {
  // A tiled file whose only attribute is "c": the library took defaults and allocated 2 GB.
  const fs::path file =
      fs::path(ARPIPE_SOURCE_DIR) / "tests" / "fuzz" / "regressions" / "fuzz_openexr" / "header-attribute-2gb-alloc.exr";
  try {
    read_openexr(file);
    ADD_FAILURE() << "expected an AssetError";
  } catch (const AssetError& e) {
    EXPECT_EQ(std::string(e.what()), file.string() + ": OpenEXR header (byte 22): the required attribute \"channels\" "
                                                     "(chlist) is missing");
  }
}

}  // namespace
}  // namespace arpipe
