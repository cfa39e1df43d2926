// Recording format v1: what the writer writes, the reader gives back exactly (pixels in every
// format, every metadata field, ground truth, the camera model), and the writer refuses bad input.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>

#include "capture/recording/recording_reader.h"
#include "capture/recording/recording_writer.h"
#include "capture_test_support.h"

namespace arpipe {
namespace {

using namespace arpipe::test;

void expect_same_metadata(const FrameMetadata& a, const FrameMetadata& b) {
  EXPECT_EQ(a.sequence, b.sequence);
  EXPECT_EQ(a.exposure_start_ns, b.exposure_start_ns);
  EXPECT_EQ(a.exposure_ns, b.exposure_ns);
  EXPECT_EQ(a.readout_ns, b.readout_ns);
  EXPECT_EQ(a.frame_duration_ns, b.frame_duration_ns);
  // Gains are written with round-trip precision (nlohmann-json prints the shortest exact decimal).
  EXPECT_EQ(a.analogue_gain, b.analogue_gain);
  EXPECT_EQ(a.digital_gain, b.digital_gain);
  EXPECT_EQ(a.raw_timestamp_ns, b.raw_timestamp_ns);
  EXPECT_EQ(a.raw_timestamp_meaning, b.raw_timestamp_meaning);
  EXPECT_EQ(a.timestamp_offset_ns, b.timestamp_offset_ns);
  EXPECT_EQ(a.lux, b.lux);
  EXPECT_EQ(a.colour_temperature_k, b.colour_temperature_k);
  EXPECT_EQ(a.raw, b.raw);
}

// Poses pass through a rotation vector printed exactly, then Rodrigues: a few ulps of drift.
void expect_same_pose(const SE3& a, const SE3& b) {
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(a.translation()[i], b.translation()[i], 1e-15);
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(a.rotation()[i][j], b.rotation()[i][j], 1e-14);
  }
}

struct FormatCase {
  PixelFormat format;
  size_t extra_stride;  // padding beyond the minimum bytes per line
};

class RecordingRoundTrip : public ::testing::TestWithParam<FormatCase> {};

TEST_P(RecordingRoundTrip, EveryFieldComesBack) {
  const auto [format, extra_stride] = GetParam();
  const int width = 64, height = 48, count = 4;
  const fs::path dir = scratch_dir(fmt::format("roundtrip-{}-{}", pixel_format_name(format), extra_stride));
  const size_t stride = min_bytes_per_line(format, width) + extra_stride;
  write_recording(dir, format, width, height, count, true, stride);

  RecordingReader reader(dir);
  EXPECT_TRUE(reader.warnings().empty());
  EXPECT_EQ(reader.info().version, 1);
  EXPECT_EQ(reader.info().pixel_format, format);
  EXPECT_EQ(reader.info().width, width);
  EXPECT_EQ(reader.info().height, height);
  EXPECT_EQ(reader.info().bytes_per_line, stride);
  EXPECT_EQ(reader.info().source, "unit test");
  EXPECT_EQ(reader.info().created_utc.size(), std::string("2024-05-01T12:00:00Z").size());
  const CameraModel expected_model = small_camera(width, height);
  EXPECT_EQ(reader.camera_model().lensmodel(), expected_model.lensmodel());
  EXPECT_EQ(reader.camera_model().intrinsics(), expected_model.intrinsics());
  ASSERT_EQ(reader.frame_count(), size_t(count));
  ASSERT_EQ(reader.ground_truth().size(), size_t(count));
  for (int i = 0; i < count; ++i) {
    const Frame written = random_frame(format, width, height, stride, uint64_t(i));
    Frame read;
    reader.read(size_t(i), read);
    EXPECT_EQ(read.format, format);
    EXPECT_EQ(read.width, width);
    EXPECT_EQ(read.height, height);
    EXPECT_EQ(read.bytes_per_line, stride);
    EXPECT_EQ(read.data, written.data) << "frame " << i;
    expect_same_metadata(read.meta, written.meta);
    expect_same_metadata(reader.metadata(size_t(i)), written.meta);
    const GroundTruthFrame truth = truth_for(written, uint64_t(i));
    EXPECT_EQ(reader.ground_truth()[size_t(i)].sequence, truth.sequence);
    expect_same_pose(reader.ground_truth()[size_t(i)].T_cam_world_start, truth.T_cam_world_start);
    expect_same_pose(reader.ground_truth()[size_t(i)].T_cam_world_mid, truth.T_cam_world_mid);
    expect_same_pose(reader.ground_truth()[size_t(i)].T_cam_world_end, truth.T_cam_world_end);
  }
}

INSTANTIATE_TEST_SUITE_P(AllFormats, RecordingRoundTrip,
                         ::testing::Values(FormatCase{PixelFormat::GREY, 0}, FormatCase{PixelFormat::RGB24, 0},
                                           FormatCase{PixelFormat::YUYV, 0}, FormatCase{PixelFormat::NV12, 0},
                                           FormatCase{PixelFormat::NV12, 16}, FormatCase{PixelFormat::RGB24, 8}),
                         [](const auto& info) {
                           return fmt::format("{}_stride_plus_{}", pixel_format_name(info.param.format),
                                              info.param.extra_stride);
                         });

TEST(RecordingWriter, WritesTheDocumentedFiles) {
  const fs::path dir = scratch_dir("documented-files");
  write_recording(dir, PixelFormat::GREY, 16, 8, 2);
  for (const char* name : {"recording.json", "camera.cameramodel", "frames.bin", "frames.jsonl", "ground_truth.jsonl"})
    EXPECT_TRUE(fs::exists(dir / name)) << name;
  EXPECT_EQ(fs::file_size(dir / "frames.bin"), 2u * 16 * 8);  // payloads back to back, nothing else
  const std::string info = read_file(dir / "recording.json");
  EXPECT_NE(info.find("\"format\": \"arpipe-recording\""), std::string::npos) << info;
  EXPECT_NE(info.find("\"version\": 1"), std::string::npos) << info;
  const std::string lines = read_file(dir / "frames.jsonl");
  EXPECT_EQ(std::count(lines.begin(), lines.end(), '\n'), 2);
  EXPECT_NE(lines.find("\"raw_timestamp_meaning\":\"end_of_frame\""), std::string::npos) << lines;
}

TEST(RecordingWriter, WithoutGroundTruthHasNoTruthFile) {
  const fs::path dir = scratch_dir("no-truth");
  write_recording(dir, PixelFormat::RGB24, 16, 8, 2, false);
  EXPECT_FALSE(fs::exists(dir / "ground_truth.jsonl"));
  RecordingReader reader(dir);
  EXPECT_EQ(reader.frame_count(), 2u);
  EXPECT_TRUE(reader.ground_truth().empty());
}

TEST(RecordingWriter, EmptyRecordingOpensWithNoFrames) {
  const fs::path dir = scratch_dir("empty");
  write_recording(dir, PixelFormat::GREY, 16, 8, 0);
  RecordingReader reader(dir);
  EXPECT_EQ(reader.frame_count(), 0u);
  EXPECT_TRUE(reader.warnings().empty());
}

TEST(RecordingWriter, RefusesToOverwriteARecording) {
  const fs::path dir = scratch_dir("overwrite");
  write_recording(dir, PixelFormat::GREY, 16, 8, 1);
  const std::string before = read_file(dir / "frames.bin");
  RecordingInfo info;
  info.pixel_format = PixelFormat::GREY;
  info.width = 16;
  info.height = 8;
  const std::string message = error_message([&] { RecordingWriter again(dir, info, small_camera(16, 8)); });
  EXPECT_NE(message.find(dir.string()), std::string::npos) << message;
  EXPECT_NE(message.find("refusing to overwrite"), std::string::npos) << message;
  EXPECT_EQ(read_file(dir / "frames.bin"), before);  // nothing already recorded is lost
}

TEST(RecordingWriter, RefusesADirectoryWithALeftoverPart) {
  const fs::path dir = scratch_dir("leftover");
  write_file(dir / "ground_truth.jsonl", "{}\n");
  RecordingInfo info;
  info.pixel_format = PixelFormat::GREY;
  info.width = 16;
  info.height = 8;
  const std::string message = error_message([&] { RecordingWriter w(dir, info, small_camera(16, 8)); });
  EXPECT_NE(message.find((dir / "ground_truth.jsonl").string() + ": exists already"), std::string::npos) << message;
  EXPECT_FALSE(fs::exists(dir / "recording.json"));
}

TEST(RecordingWriter, RefusesFramesThatDoNotMatchTheRecording) {
  const fs::path dir = scratch_dir("mismatch");
  RecordingInfo info;
  info.pixel_format = PixelFormat::YUYV;
  info.width = 16;
  info.height = 8;
  RecordingWriter writer(dir, info, small_camera(16, 8));
  Frame wrong_format = random_frame(PixelFormat::GREY, 16, 8, 16, 0);
  std::string message = error_message([&] { writer.append(wrong_format); });
  EXPECT_NE(message.find("frame 0 is 16x8 GREY"), std::string::npos) << message;
  Frame wrong_size = random_frame(PixelFormat::YUYV, 18, 8, 36, 0);
  message = error_message([&] { writer.append(wrong_size); });
  EXPECT_NE(message.find("18x8"), std::string::npos) << message;
  EXPECT_EQ(writer.frames_written(), 0u);
}

TEST(RecordingWriter, GroundTruthForEveryFrameOrNone) {
  const fs::path dir = scratch_dir("truth-mixed");
  RecordingInfo info;
  info.pixel_format = PixelFormat::GREY;
  info.width = 16;
  info.height = 8;
  RecordingWriter writer(dir, info, small_camera(16, 8));
  const Frame f0 = random_frame(PixelFormat::GREY, 16, 8, 16, 0);
  writer.append(f0, truth_for(f0, 0));
  const Frame f1 = random_frame(PixelFormat::GREY, 16, 8, 16, 1);
  const std::string message = error_message([&] { writer.append(f1); });
  EXPECT_NE(message.find("frame 1 has no ground truth"), std::string::npos) << message;
  writer.append(f1, truth_for(f1, 1));  // a refused append leaves the writer usable
  EXPECT_EQ(writer.frames_written(), 2u);
  EXPECT_EQ(RecordingReader(dir).frame_count(), 2u);
}

TEST(RecordingWriter, RefusesACameraModelOfAnotherSize) {
  const fs::path dir = scratch_dir("model-size");
  RecordingInfo info;
  info.pixel_format = PixelFormat::GREY;
  info.width = 16;
  info.height = 8;
  const std::string message = error_message([&] { RecordingWriter w(dir, info, small_camera(32, 8)); });
  EXPECT_NE(message.find("32x8 differs from the frame size 16x8"), std::string::npos) << message;
}

TEST(RecordingWriter, RefusesAnInvalidImageSize) {
  const fs::path dir = scratch_dir("odd-size");
  RecordingInfo info;
  info.pixel_format = PixelFormat::NV12;
  info.width = 15;
  info.height = 8;
  const std::string message = error_message([&] { RecordingWriter w(dir, info, small_camera(15, 8)); });
  EXPECT_NE(message.find("NV12 needs an even width"), std::string::npos) << message;
}

// The simulator's extra ground truth (rows, lights, sun, exposure, linear image) comes back as written.
TEST(RecordingWriter, SimulatorGroundTruthRoundTrips) {
  const fs::path dir = scratch_dir("truth-extra");
  const RecordingInfo info{kRecordingFormatVersion, PixelFormat::GREY, 8, 4, 0, "test", ""};
  {
    RecordingWriter writer(dir, info, CameraModel::pinhole(10, 10, 3.5, 1.5, 8, 4));
    const Frame f = random_frame(PixelFormat::GREY, 8, 4, writer.info().bytes_per_line, 0);
    GroundTruthFrame truth = truth_for(f, 0);
    truth.rows = {{0, SE3::from_rt({0.1, 0.2, 0.3}, {1, 2, 3})}, {3, SE3::from_rt({0.1, 0.2, 0.31}, {1, 2, 3.5})}};
    truth.lights = {{"sun", "directional", {0.0, -0.6, 0.8}, {0, 0, 0}, {1.0, 0.9, 0.8}, 900.0, 0.00925, 0.0},
                    {"lamp", "sphere", {0, 0, 0}, {0.5, -0.25, 1.5}, {1, 1, 1}, 12.5, 0.0, 0.05},
                    {"bulb", "point", {0, 0, 0}, {0.1, 0.2, 0.3}, {0.5, 0.5, 1}, 3.0, 0.0, 0.0}};
    truth.sun = GroundTruthSun{3.3919, 0.6959};
    truth.exposure_ns = 7'654'321;
    truth.analogue_gain = 2.5;
    truth.digital_gain = 1.25;
    truth.linear_image = "linear_000000.pfm";
    writer.append(f, truth);
  }
  const RecordingReader reader(dir);
  ASSERT_EQ(reader.ground_truth().size(), 1u);
  const GroundTruthFrame& back = reader.ground_truth()[0];
  ASSERT_EQ(back.rows.size(), 2u);
  EXPECT_EQ(back.rows[1].row, 3);
  expect_same_pose(back.rows[1].T_cam_world, SE3::from_rt({0.1, 0.2, 0.31}, {1, 2, 3.5}));
  ASSERT_EQ(back.lights.size(), 3u);
  EXPECT_EQ(back.lights[1], (GroundTruthLight{"lamp", "sphere", {0, 0, 0}, {0.5, -0.25, 1.5}, {1, 1, 1}, 12.5, 0.0, 0.05}));
  EXPECT_EQ(back.lights[2].kind, "point");
  // Angles pass through degrees in the file: a few ulps.
  EXPECT_NEAR(back.lights[0].angular_diameter_rad, 0.00925, 1e-15);
  ASSERT_TRUE(back.sun.has_value());
  EXPECT_NEAR(back.sun->azimuth_rad, 3.3919, 1e-14);
  EXPECT_NEAR(back.sun->elevation_rad, 0.6959, 1e-14);
  EXPECT_EQ(back.exposure_ns, 7'654'321);
  EXPECT_EQ(back.analogue_gain, 2.5);
  EXPECT_EQ(back.digital_gain, 1.25);
  EXPECT_EQ(back.linear_image, "linear_000000.pfm");
}

}  // namespace
}  // namespace arpipe
