// Panorama videos: every frame's index from its presentation time equals the index drawn into it
// (a barcode), through B-frames and an MP4 edit list (x264), in WebM (VP9), after 100 random seeks
// and over a 10-minute loop; bad files refused with their name, and files whose spherical metadata
// says cubemap, cropped or stereo refused for that. The videos are made here with Debian's ffmpeg
// command from raw frames (and remuxed with the metadata through FFmpeg's libraries).
extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/spherical.h>
#include <libavutil/stereo3d.h>
}

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <optional>
#include <random>
#include <tuple>

#include "capture/panorama/panorama_source.h"
#include "capture/panorama/panorama_video.h"
#include "core/scene/asset_error.h"
#include "tests/capture/capture_test_support.h"
#include "tests/support/barcode_video.h"

namespace arpipe {
namespace {

namespace fs = std::filesystem;
constexpr int kWidth = test::kBarcodeWidth;

int read_barcode(const PanoramaVideoFrame& frame) { return test::read_barcode(frame.rgb, frame.width); }

fs::path make_video(const fs::path& dir, const std::string& name, int frames, const std::string& codec) {
  return test::make_barcode_video(dir, name, frames, codec);
}

const fs::path& h264_with_b_frames() {
  static const fs::path file =
      make_video(test::scratch_dir("panorama-video"), "b-frames.mp4", 64, test::kH264WithBFrames);
  return file;
}

// How many frames of each picture type ffprobe finds, as "B 37 I 3 P 24 ".
std::string picture_types(const fs::path& file) {
  const std::string command = fmt::format(
      "ffprobe -v error -select_streams v -show_entries frame=pict_type -of csv=p=0 '{}' | cut -c1 | sort | uniq -c | "
      "awk '{{printf \"%s %s \", $2, $1}}'",
      file.string());
  FILE* pipe = popen(command.c_str(), "r");
  std::string out;
  char buffer[256];
  while (pipe && fgets(buffer, sizeof buffer, pipe)) out += buffer;
  if (pipe) pclose(pipe);
  return out;
}

TEST(PanoramaVideo, EveryFrameKnowsItsIndexThroughBFramesAndTheEditList) {
  // The file does have B-frames (decoded out of order) and an edit list (x264's delay of 2 frames).
  const std::string types = picture_types(h264_with_b_frames());
  ASSERT_NE(types.find("B "), std::string::npos) << types;
  EXPECT_GT(std::stoi(types.substr(types.find("B ") + 2)), 10) << types;
  PanoramaVideo video(h264_with_b_frames());
  EXPECT_EQ(video.width(), kWidth);
  EXPECT_EQ(video.rate_num(), 30);
  EXPECT_EQ(video.rate_den(), 1);
  PanoramaVideoFrame frame;
  int count = 0;
  while (video.next(frame)) {
    EXPECT_EQ(frame.index, count);
    EXPECT_EQ(read_barcode(frame), frame.index);
    EXPECT_EQ(frame.time_ns, (frame.index * 1'000'000'000 + 15) / 30);  // the index's time, to the ns
    ++count;
  }
  EXPECT_EQ(count, 64);
  EXPECT_EQ(video.decode_errors(), 0u);
}

TEST(PanoramaVideo, WebmVp9Too) {
  PanoramaVideo video(make_video(test::scratch_dir("panorama-webm"), "vp9.webm", 40, "-c:v libvpx-vp9 -crf 20 -b:v 0 -g 12"));
  PanoramaVideoFrame frame;
  int count = 0;
  while (video.next(frame)) {
    EXPECT_EQ(frame.index, count);
    EXPECT_EQ(read_barcode(frame), frame.index);
    ++count;
  }
  EXPECT_EQ(count, 40);
}

TEST(PanoramaVideo, HardwareDecodingWhereTheBoardHasNoneIsSoftwareDecoding) {
  // Asked for the board's V4L2 memory-to-memory decoder: on a machine without one (this one), the
  // software decoder, every frame at its index; on a board with one, the same frames from it.
  PanoramaVideo video(h264_with_b_frames(), PanoramaLayout::Auto, true);
  std::printf("decoded by: %s\n", video.describe().c_str());
  EXPECT_TRUE(video.describe().rfind("h264 ", 0) == 0 || video.describe().rfind("h264_v4l2m2m ", 0) == 0) << video.describe();
  PanoramaVideoFrame frame;
  for (int k = 0; k < 64; ++k) {
    ASSERT_TRUE(video.next(frame)) << k;
    EXPECT_EQ(frame.index, k);
    EXPECT_EQ(read_barcode(frame), k);
  }
}

TEST(PanoramaVideo, AHundredRandomSeeksLandOnTheirFrame) {
  PanoramaVideo video(h264_with_b_frames());
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> index(0, 63);
  PanoramaVideoFrame frame;
  for (int k = 0; k < 100; ++k) {
    const int target = index(rng);
    video.seek(target);
    ASSERT_TRUE(video.next(frame)) << "seek to " << target;
    EXPECT_EQ(frame.index, target);
    EXPECT_EQ(read_barcode(frame), target);
    if (target < 63) {  // and decoding goes on from there
      ASSERT_TRUE(video.next(frame));
      EXPECT_EQ(read_barcode(frame), target + 1);
    }
  }
}

TEST(PanoramaVideo, TenMinutesOfLoopsNeverDrift) {
  // 64 frames at 30 frames/s looped for 10 minutes: 18000 frames, each index the barcode's.
  PanoramaVideo video(h264_with_b_frames());
  PanoramaVideoFrame frame;
  for (int shown = 0; shown < 18000;) {
    if (!video.next(frame)) {
      video.seek(0);
      continue;
    }
    ASSERT_EQ(frame.index, shown % 64) << "frame " << shown;
    ASSERT_EQ(read_barcode(frame), frame.index) << "frame " << shown;
    ++shown;
  }
}

TEST(PanoramaVideo, TheSourceShowsEachOutputFrameTheVideoFrameOfItsTime) {
  // A view whose centre pixel looks at bit 0's block (column 8, the equator): at 60 frames/s out of
  // a 30 frames/s video each video frame shows twice, and the loop starts again after frame 63.
  SourceConfig config;
  config.type = SourceType::Panorama;
  config.pacing = ReplayPacing::Fast;
  config.panorama.file = h264_with_b_frames();
  config.panorama.view.width = 64;
  config.panorama.view.height = 32;
  config.panorama.view.fps = 60;
  config.panorama.view.frames = 300;
  config.panorama.view.yaw_rad = (8.5 / kWidth - 0.5) * 2 * M_PI;
  PanoramaSource source(config);
  Frame frame;
  for (int k = 0; k < 300; ++k) {
    ASSERT_EQ(source.next(frame), SourceStatus::Frame);
    ASSERT_TRUE(frame.meta.source_frame_index);
    EXPECT_EQ(*frame.meta.source_frame_index, (k / 2) % 64) << "output frame " << k;
    // The animation's time (render/proxy_animator.h) is that index over the video's 30 frames/s.
    ASSERT_TRUE(frame.meta.source_frame_time_ns);
    EXPECT_EQ(*frame.meta.source_frame_time_ns, (int64_t((k / 2) % 64) * 1'000'000'000 + 15) / 30) << "output frame " << k;
    const uint8_t centre = frame.data[16 * frame.bytes_per_line + 3 * 32];
    EXPECT_EQ(centre > 128, bool(*frame.meta.source_frame_index & 1)) << "output frame " << k << ": " << int(centre);
  }
  EXPECT_EQ(source.next(frame), SourceStatus::EndOfStream);
}

// Opening `file` must fail with an AssetError naming it and saying `expected`.
void refused(const fs::path& file, const std::string& expected, PanoramaLayout layout = PanoramaLayout::Equirect) {
  try {
    PanoramaVideo video(file, layout);
    ADD_FAILURE() << file << " was accepted";
  } catch (const AssetError& e) {
    EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
  }
}

TEST(PanoramaVideo, BadFilesAreRefusedNamingThem) {
  const fs::path dir = test::scratch_dir("panorama-video-bad");
  refused(dir / "missing.mp4", "no such file");
  std::ofstream(dir / "text.mp4") << "not a video\n";
  refused(dir / "text.mp4", "cannot open");
  // Cut in half: the index (moov) is at the end of ffmpeg's MP4s, so nothing is readable.
  std::ifstream in(h264_with_b_frames(), std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::ofstream(dir / "cut.mp4", std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  refused(dir / "cut.mp4", "cut.mp4");
  // Not 2:1.
  const fs::path square = dir / "square.mp4";
  EXPECT_EQ(std::system(fmt::format("ffmpeg -nostdin -v error -y -f lavfi -i color=c=gray:s=64x64:d=0.2 -c:v libx264 '{}'",
                                    square.string()).c_str()),
            0);
  refused(square, "not a panorama");
}

// Copies the MP4 `in` to `out` with spherical metadata on its video stream, written as Google's
// Spherical Video V2 boxes (sv3d, st3d: FFmpeg's MP4 muxer writes them at "unofficial" strictness).
void remux_with_metadata(const fs::path& in, const fs::path& out, std::optional<AVSphericalProjection> projection,
                         uint32_t bound_right, std::optional<AVStereo3DType> stereo) {
  AVFormatContext* input = nullptr;
  ASSERT_EQ(avformat_open_input(&input, in.c_str(), nullptr, nullptr), 0);
  ASSERT_GE(avformat_find_stream_info(input, nullptr), 0);
  AVFormatContext* output = nullptr;
  ASSERT_GE(avformat_alloc_output_context2(&output, nullptr, "mp4", out.c_str()), 0);
  AVStream* stream = avformat_new_stream(output, nullptr);
  ASSERT_NE(stream, nullptr);
  ASSERT_GE(avcodec_parameters_copy(stream->codecpar, input->streams[0]->codecpar), 0);
  stream->codecpar->codec_tag = 0;
  stream->time_base = input->streams[0]->time_base;
  if (projection) {
    size_t size = 0;
    AVSphericalMapping* mapping = av_spherical_alloc(&size);
    mapping->projection = *projection;
    mapping->bound_right = bound_right;
    ASSERT_EQ(av_stream_add_side_data(stream, AV_PKT_DATA_SPHERICAL, reinterpret_cast<uint8_t*>(mapping), size), 0);
  }
  if (stereo) {
    AVStereo3D* s3d = av_stereo3d_alloc();
    s3d->type = *stereo;
    ASSERT_EQ(av_stream_add_side_data(stream, AV_PKT_DATA_STEREO3D, reinterpret_cast<uint8_t*>(s3d), sizeof(AVStereo3D)), 0);
  }
  output->strict_std_compliance = FF_COMPLIANCE_UNOFFICIAL;
  ASSERT_GE(avio_open(&output->pb, out.c_str(), AVIO_FLAG_WRITE), 0);
  ASSERT_GE(avformat_write_header(output, nullptr), 0);
  AVPacket* packet = av_packet_alloc();
  while (av_read_frame(input, packet) >= 0) {
    av_packet_rescale_ts(packet, input->streams[0]->time_base, stream->time_base);
    packet->stream_index = 0;
    ASSERT_GE(av_interleaved_write_frame(output, packet), 0);
  }
  ASSERT_EQ(av_write_trailer(output), 0);
  av_packet_free(&packet);
  avio_closep(&output->pb);
  avformat_free_context(output);
  avformat_close_input(&input);
}

TEST(PanoramaVideo, SphericalMetadataThatIsNotMonoEquirectangularIsRefusedForWhatItSays) {
  const fs::path dir = test::scratch_dir("panorama-video-metadata");
  const fs::path plain = make_video(dir, "plain.mp4", 8, "-c:v libx264 -preset veryfast");
  // Mono equirectangular, said so: read as before, every frame its own index.
  remux_with_metadata(plain, dir / "equirect.mp4", AV_SPHERICAL_EQUIRECTANGULAR, 0, AV_STEREO3D_2D);
  {
    PanoramaVideo video(dir / "equirect.mp4");
    PanoramaVideoFrame frame;
    for (int i = 0; i < 8; ++i) {
      ASSERT_TRUE(video.next(frame)) << i;
      EXPECT_EQ(read_barcode(frame), frame.index);
    }
  }
  remux_with_metadata(plain, dir / "cubemap.mp4", AV_SPHERICAL_CUBEMAP, 0, std::nullopt);
  refused(dir / "cubemap.mp4", "the cubemap projection; only equirectangular");
  remux_with_metadata(plain, dir / "cropped.mp4", AV_SPHERICAL_EQUIRECTANGULAR_TILE, 1u << 30, std::nullopt);
  refused(dir / "cropped.mp4", "crops the sphere");
  // A layout the config does not say, or a shape that cannot hold it. (Packings other than
  // top/bottom and side by side are refused too; MP4's st3d box cannot hold them.)
  remux_with_metadata(plain, dir / "stereo.mp4", std::nullopt, 0, AV_STEREO3D_TOPBOTTOM);
  refused(dir / "stereo.mp4", "its metadata says the layout is \"equirect-tb\" but source.panorama.layout is \"equirect\"",
          PanoramaLayout::Equirect);
  refused(dir / "stereo.mp4", "is not 1:1", PanoramaLayout::EquirectTopBottom);
  refused(dir / "stereo.mp4", "is not 1:1", PanoramaLayout::Auto);  // "auto": the metadata's word over the 2:1 shape
  refused(dir / "stereo.mp4", "says the layout is \"equirect-tb\" but source.panorama.layout is \"equirect-lr\"",
          PanoramaLayout::EquirectLeftRight);
  refused(dir / "equirect.mp4", "says the layout is \"equirect\" but source.panorama.layout is \"equirect-tb\"",
          PanoramaLayout::EquirectTopBottom);
  fs::remove_all(dir);
}

TEST(PanoramaVideo, AStereoVideoGivesEachTimeStepItsLeftThenItsRightEye) {
  // Top/bottom: the left eye red (on top), the right blue; and the same side by side.
  const fs::path dir = test::scratch_dir("panorama-video-stereo");
  for (const auto& [layout, stack, size] : {std::tuple{PanoramaLayout::EquirectTopBottom, "vstack", "64x64"},
                                            std::tuple{PanoramaLayout::EquirectLeftRight, "hstack", "128x32"}}) {
    const fs::path file = dir / fmt::format("{}.mp4", stack);
    ASSERT_EQ(std::system(fmt::format("ffmpeg -nostdin -v error -y -f lavfi -i 'color=c=red:s=64x32:r=30:d=0.2[a];"
                                      "color=c=blue:s=64x32:r=30:d=0.2[b];[a][b]{}' -c:v libx264 -pix_fmt yuv444p '{}'",
                                      stack, file.string())
                                  .c_str()),
              0);
    {
      const PanoramaVideo video(file, layout);
      EXPECT_EQ(fmt::format("{}x{}", video.width(), video.height()), size);
      // "auto": the shape says it (the file has no stereo metadata).
      EXPECT_EQ(PanoramaVideo(file).layout(), layout);
    }
    SourceConfig config;
    config.type = SourceType::Panorama;
    config.pacing = ReplayPacing::Fast;
    config.panorama.file = file;
    config.panorama.layout = layout;
    config.panorama.view.width = 16;
    config.panorama.view.height = 8;
    config.panorama.view.fps = 30;
    config.panorama.view.frames = 3;
    PanoramaSource source(config);
    Frame frame;
    for (int k = 0; k < 6; ++k) {
      ASSERT_EQ(source.next(frame), SourceStatus::Frame) << k;
      EXPECT_EQ(frame.meta.sequence, uint64_t(k));
      EXPECT_EQ(frame.meta.eye, k % 2 == 0 ? Eye::Left : Eye::Right) << k;
      EXPECT_EQ(frame.meta.exposure_start_ns, std::llround((k / 2) * 1e9 / 30)) << k;  // k / fps exactly, rounded
      const uint8_t* centre = frame.data.data() + 4 * frame.bytes_per_line + 3 * 8;
      if (k % 2 == 0) EXPECT_TRUE(centre[0] > 200 && centre[2] < 60) << stack << " frame " << k << ": not red";
      else EXPECT_TRUE(centre[2] > 200 && centre[0] < 60) << stack << " frame " << k << ": not blue";
    }
    EXPECT_EQ(source.next(frame), SourceStatus::EndOfStream);
  }
  fs::remove_all(dir);
}

TEST(PanoramaVideo, FramesOfAnotherSizeAreSkippedCountedAndTheSourceSaysSo) {
  // One H.264 stream whose middle second is 128 x 64 (in-band headers switch the decoder), in a
  // Matroska file whose header says 256 x 128: 30 frames of each size, three runs.
  const fs::path dir = test::scratch_dir("panorama-video-resized");
  const auto run = [](const std::string& command) { EXPECT_EQ(std::system(command.c_str()), 0) << command; };
  for (const auto& [name, size] : {std::pair{"a", "256x128"}, {"b", "128x64"}})
    run(fmt::format("ffmpeg -nostdin -v error -y -f lavfi -i testsrc2=s={}:r=30:d=1 -c:v libx264 -x264-params "
                    "repeat-headers=1 -bf 0 -pix_fmt yuv420p '{}'", size, (dir / (std::string(name) + ".h264")).string()));
  run(fmt::format("cd '{}' && cat a.h264 b.h264 a.h264 > c.h264 && ffmpeg -nostdin -v error -y -r 30 -i c.h264 -c copy c.mkv",
                  dir.string()));
  {
    PanoramaVideo video(dir / "c.mkv");
    PanoramaVideoFrame frame;
    int delivered = 0;
    while (video.next(frame)) {
      EXPECT_EQ(frame.width, 256);
      EXPECT_EQ(frame.height, 128);
      ++delivered;
    }
    EXPECT_EQ(delivered, 60);
    EXPECT_EQ(video.decode_errors(), 30u);
  }
  // Through the source: every output frame still comes, and its health counts the skipped ones.
  SourceConfig config;
  config.type = SourceType::Panorama;
  config.pacing = ReplayPacing::Fast;
  config.panorama.file = dir / "c.mkv";
  config.panorama.view.width = 32;
  config.panorama.view.height = 16;
  config.panorama.view.fps = 30;
  config.panorama.view.frames = 90;
  PanoramaSource source(config);
  EXPECT_EQ(source.health(), "");
  Frame frame;
  for (int i = 0; i < 90; ++i) ASSERT_EQ(source.next(frame), SourceStatus::Frame) << i;
  EXPECT_NE(source.health().find("video frames skipped 30"), std::string::npos) << source.health();
  fs::remove_all(dir);
}

}  // namespace
}  // namespace arpipe
