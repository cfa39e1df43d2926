// The JSON text of recording format v1 (recording.json, frames.jsonl, ground_truth.jsonl), shared by
// the reader and the writer so both spell every field the same way. Internal to capture/.
#pragma once

#include <cstdint>
#include <string>

#include "capture/recording/recording_format.h"
#include "core/frame.h"

namespace arpipe::recording_json {

// recording.json "files": the names of the parts, relative to the recording directory.
struct FileNames {
  std::string camera_model = kRecordingCameraModelFile;
  std::string frames = kRecordingFramesFile;
  std::string metadata = kRecordingMetadataFile;
  std::string ground_truth = kRecordingGroundTruthFile;
};

// One line of frames.jsonl: where the payload lies in frames.bin, its checksum, its metadata.
struct FrameRecord {
  uint64_t index = 0;
  uint64_t offset = 0;
  uint64_t size = 0;
  uint32_t crc32 = 0;
  FrameMetadata meta;
};

struct GroundTruthRecord {
  uint64_t index = 0;
  GroundTruthFrame truth;
};

std::string encode_info(const RecordingInfo& info, const FileNames& files);
// where: the file name for messages. Throws RecordingError naming it and the byte offset or field.
void decode_info(const std::string& text, const std::string& where, RecordingInfo& info, FileNames& files);

// One line without its newline.
std::string encode_frame_record(const FrameRecord& record);
// where: "<file> line N". Throws RecordingError naming it, the column or the field.
FrameRecord decode_frame_record(const std::string& line, const std::string& where);

std::string encode_ground_truth(const GroundTruthRecord& record);
GroundTruthRecord decode_ground_truth(const std::string& line, const std::string& where);

}  // namespace arpipe::recording_json
