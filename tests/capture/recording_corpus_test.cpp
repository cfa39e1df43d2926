// The seed recording for the recording fuzz target (tests/capture/corpus/recording) stays valid:
// it opens without warnings and every frame passes its checksum.
#include <gtest/gtest.h>

#include <filesystem>

#include "capture/recording/recording_reader.h"

namespace arpipe {
namespace {

namespace fs = std::filesystem;

TEST(RecordingCorpus, TheSeedRecordingOpensCleanly) {
  const fs::path dir = fs::path(ARPIPE_SOURCE_DIR) / "tests" / "capture" / "corpus" / "recording";
  const RecordingReader reader(dir);
  EXPECT_TRUE(reader.warnings().empty());
  ASSERT_EQ(reader.frame_count(), 3u);
  ASSERT_EQ(reader.ground_truth().size(), 3u);
  EXPECT_EQ(reader.ground_truth()[1].lights.size(), 2u);
  Frame frame;
  for (size_t i = 0; i < reader.frame_count(); ++i) EXPECT_NO_THROW(reader.read(i, frame)) << i;
  uintmax_t bytes = 0;
  for (const auto& entry : fs::directory_iterator(dir)) bytes += entry.file_size();
  EXPECT_LT(bytes, 50u * 1024);
}

}  // namespace
}  // namespace arpipe
