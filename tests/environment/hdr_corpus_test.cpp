// The seed corpus for the Radiance fuzz target (tests/environment/corpus) stays valid: every file decodes
// to the size its resolution line declares.
#include <gtest/gtest.h>

#include <filesystem>

#include "core/image/hdr_file.h"

namespace arpipe {
namespace {

namespace fs = std::filesystem;

TEST(HdrCorpus, EverySeedDecodes) {
  const fs::path corpus = fs::path(ARPIPE_SOURCE_DIR) / "tests" / "environment" / "corpus";
  int seeds = 0;
  for (const auto& entry : fs::directory_iterator(corpus)) {
    const HdrImage image = read_hdr_image(entry.path());
    EXPECT_GT(image.width * image.height, 0) << entry.path();
    ++seeds;
  }
  EXPECT_GE(seeds, 3);
}

}  // namespace
}  // namespace arpipe
