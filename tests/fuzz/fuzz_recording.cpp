// libFuzzer target: the recording reader (capture/recording RecordingReader: recording.json, the
// camera model, frames.jsonl, ground_truth.jsonl, frames.bin). An input is the directory's files
// in that order, separated by kPartSeparator; a part left out is a missing file. Bad input must be
// a RecordingError; every frame the reader counts must read (or fail with a RecordingError).
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string_view>

#include "capture/recording/recording_format.h"
#include "capture/recording/recording_reader.h"
#include "core/frame.h"
#include "tests/fuzz/fuzz_check.h"
#include "tests/fuzz/fuzz_temp_dir.h"

namespace {

// A line that none of the text parts holds; frames.bin comes last so that its bytes need none.
constexpr std::string_view kPartSeparator = "\n--arpipe-fuzz-part--\n";
constexpr std::array<std::string_view, 5> kPartNames = {"recording.json", "camera.cameramodel", "frames.jsonl",
                                                        "ground_truth.jsonl", "frames.bin"};
constexpr size_t kMaxFramesRead = 8;  // enough to reach every branch of read(); keeps runs fast

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::filesystem::path dir = arpipe::fuzz::temp_dir() / "recording";
  std::error_code ec;
  std::filesystem::remove_all(dir, ec);
  std::filesystem::create_directory(dir);
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  size_t start = 0;
  for (size_t part = 0; part < kPartNames.size() && start <= input.size(); ++part) {
    const size_t end = part + 1 < kPartNames.size() ? std::min(input.find(kPartSeparator, start), input.size())
                                                    : input.size();
    const std::string name = "recording/" + std::string(kPartNames[part]);
    arpipe::fuzz::write_temp_file(name, data + start, end - start);
    start = end + kPartSeparator.size();
  }
  try {
    const arpipe::RecordingReader reader(dir);
    const arpipe::RecordingInfo& info = reader.info();
    ARPIPE_FUZZ_CHECK(info.width >= 1 && info.height >= 1, "a frame size");
    ARPIPE_FUZZ_CHECK(reader.ground_truth().empty() || reader.ground_truth().size() == reader.frame_count(),
                      "ground truth for every frame or none");
    arpipe::Frame frame;
    for (size_t i = 0; i < std::min(reader.frame_count(), kMaxFramesRead); ++i) {
      (void)reader.metadata(i);
      try {
        reader.read(i, frame);
        ARPIPE_FUZZ_CHECK(frame.width == info.width && frame.height == info.height, "the recording's frame size");
      } catch (const arpipe::RecordingError&) {
      }
    }
  } catch (const arpipe::RecordingError&) {
  }
  return 0;
}
