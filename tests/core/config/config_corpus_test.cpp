// The seed corpus for the config fuzz target (tests/core/corpus/config) stays valid: every file
// loads, so the fuzzer starts from configs that reach every part of the schema walk.
#include <gtest/gtest.h>

#include <filesystem>

#include "core/config/config.h"

namespace arpipe {
namespace {

namespace fs = std::filesystem;

TEST(ConfigCorpus, EverySeedLoads) {
  const fs::path corpus = fs::path(ARPIPE_SOURCE_DIR) / "tests" / "core" / "corpus" / "config";
  int seeds = 0;
  for (const auto& entry : fs::directory_iterator(corpus)) {
    EXPECT_NO_THROW(load_config(entry.path())) << entry.path();
    EXPECT_LT(fs::file_size(entry.path()), 50u * 1024) << entry.path();
    ++seeds;
  }
  EXPECT_GE(seeds, 4);
}

}  // namespace
}  // namespace arpipe
