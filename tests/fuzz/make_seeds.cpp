// Writes the fuzz targets' seed inputs with the project's own writers (valid files of every kind
// the parsers read), one folder per target: fuzz_make_seeds OUT_DIR (docs/FUZZING.md). The
// committed corpora (tests/fuzz/corpus) started as these.
#include <ImfRgbaFile.h>
#include <ImfTiledRgbaFile.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "calib/board_printout.h"
#include "calib/calibration_board.h"
#include "capture/recording/recording_writer.h"
#include "core/config/config.h"
#include "core/frame.h"
#include "core/geometry/camera_model.h"
#include "core/image/openexr_file.h"
#include "core/image/radiance_hdr.h"
#include "core/scene/glb_writer.h"
#include "render/prt/prt_cache.h"
#include "tests/fuzz/fuzz_boards.h"
#include "tests/scene/gltf_hostile_files.h"
#include "tests/scene/gltf_test_files.h"

namespace fs = std::filesystem;
using namespace arpipe;

namespace {

fs::path out_root;

void write(const std::string& target, const std::string& name, const std::string& bytes) {
  fs::create_directories(out_root / target);
  std::ofstream(out_root / target / name, std::ios::binary) << bytes;
}

std::string read(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// glTF's binary container: header, JSON chunk (space-padded), BIN chunk (zero-padded).
std::string glb(std::string json, std::vector<uint8_t> bin) {
  while (json.size() % 4) json += ' ';
  while (bin.size() % 4) bin.push_back(0);
  std::string out;
  const auto u32 = [&](uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); };
  out += "glTF";
  u32(2);
  u32(uint32_t(12 + 8 + json.size() + 8 + bin.size()));
  u32(uint32_t(json.size()));
  out += "JSON";
  out += json;
  u32(uint32_t(bin.size()));
  out += std::string("BIN\0", 4);
  out.append(bin.begin(), bin.end());
  return out;
}

// Animated scenes: an arm (LINEAR translation and rotation) holding a hand with a point light, a
// STEP scale and a CUBICSPLINE translation on a post; and the writer's animated nodes as a .glb.
void animated_gltf_seeds() {
  render_test::AnimatedGltf file;
  file.gltf["nodes"] = {{{"name", "arm"}, {"mesh", 0}, {"children", {1}}},
                        {{"name", "hand"}, {"mesh", 0}, {"translation", {1, 0, 0}},
                         {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}},
                        {{"name", "post"}, {"mesh", 0}, {"scale", {1, 1, 1}}}};
  file.gltf["scenes"] = {{{"nodes", {0, 2}}}};
  file.gltf["extensions"] = {{"KHR_lights_punctual", {{"lights", {{{"type", "point"}, {"intensity", 3}}}}}}};
  const int times = file.floats({0, 0.5f, 2}, "SCALAR");
  const int moves = file.floats({0, 0, 0, 0, 1, 0, 1, 1, 0}, "VEC3");
  const int turns = file.floats({0, 0, 0, 1, 0, 0.3826834f, 0, 0.9238795f, 0, 0.7071068f, 0, 0.7071068f}, "VEC4");
  const int scales = file.floats({1, 1, 1, 2, 2, 2, 0.5f, 0.5f, 0.5f}, "VEC3");
  const int cubic = file.floats({0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 1, 0, 0, 0, 0, 0, 0, 0, 2, 0, 0, 0, 0, 0}, "VEC3");
  file.gltf["animations"] = {
      {{"name", "move"},
       {"samplers", {{{"input", times}, {"output", moves}},
                     {{"input", times}, {"output", turns}, {"interpolation", "LINEAR"}},
                     {{"input", times}, {"output", scales}, {"interpolation", "STEP"}},
                     {{"input", times}, {"output", cubic}, {"interpolation", "CUBICSPLINE"}}}},
       {"channels", {{{"sampler", 0}, {"target", {{"node", 0}, {"path", "translation"}}}},
                     {{"sampler", 1}, {"target", {{"node", 0}, {"path", "rotation"}}}},
                     {{"sampler", 2}, {"target", {{"node", 2}, {"path", "scale"}}}},
                     {{"sampler", 3}, {"target", {{"node", 2}, {"path", "translation"}}}}}}}};
  write("fuzz_gltf", "animated.gltf", file.done().dump());

  Mesh triangle;
  triangle.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  triangle.indices = {0, 1, 2};
  triangle.normals = {0, 0, 1, 0, 0, 1, 0, 0, 1};
  GlbAnimatedNode arm{"arm", triangle, {{0, SE3()}, {1, SE3::from_rt({0, 0, 3}, {1, 0, 0})}, {2, SE3::from_rt({1, 0, 0}, {1, 1, 0})}}};
  GltfLight lamp;
  lamp.type = "point";
  const std::vector<uint8_t> animated = encode_glb(triangle, "fuzz_make_seeds", {lamp}, {arm});
  write("fuzz_gltf", "animated.glb", std::string(animated.begin(), animated.end()));
}

void gltf_seeds() {
  write("fuzz_gltf", "triangle.gltf", render_test::triangle_gltf());
  render_test::TriangleOptions flat;
  flat.with_normals = false;
  write("fuzz_gltf", "triangle-flat.gltf", render_test::triangle_gltf(flat));
  for (const int mode : {5, 6}) {  // strip, fan
    render_test::TriangleOptions options;
    options.mode = mode;
    write("fuzz_gltf", "triangle-mode" + std::to_string(mode) + ".gltf", render_test::triangle_gltf(options));
  }
  render_test::TriangleOptions matrix;
  matrix.node_transform = R"("matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,2,1])";
  write("fuzz_gltf", "triangle-matrix.gltf", render_test::triangle_gltf(matrix));
  // The same triangle as .glb, its buffer in the BIN chunk.
  std::vector<uint8_t> bin;
  render_test::append<float>(bin, {0, 0, 0, 1, 0, 0, 0, 1, 0});
  render_test::append<float>(bin, {0, 0, 1, 0, 0, 1, 0, 0, 1});
  render_test::append<uint16_t>(bin, {0, 1, 2});
  const std::string json = R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],
"nodes":[{"mesh":0,"rotation":[0,0,0.7071068,0.7071068],"children":[1]},{"mesh":0,"translation":[1,0,0]}],
"meshes":[{"primitives":[{"attributes":{"POSITION":0,"NORMAL":1},"indices":2}]}],
"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]},
{"bufferView":1,"componentType":5126,"count":3,"type":"VEC3"},
{"bufferView":2,"componentType":5123,"count":3,"type":"SCALAR"}],
"bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":36},{"buffer":0,"byteOffset":36,"byteLength":36},
{"buffer":0,"byteOffset":72,"byteLength":6}],
"buffers":[{"byteLength":78}]})";
  write("fuzz_gltf", "two-nodes.glb", glb(json, bin));
  animated_gltf_seeds();
}

HdrImage pattern(int width, int height) {
  HdrImage image{width, height, std::vector<float>(3 * size_t(width) * size_t(height))};
  for (size_t i = 0; i < image.rgb.size(); ++i) image.rgb[i] = float(std::ldexp(1.0 + 0.1 * double(i % 7), int(i % 9) - 4));
  return image;
}

void hdr_seeds(const fs::path& scratch) {
  write_radiance_hdr(scratch / "rle.hdr", pattern(16, 3), true);
  write("fuzz_radiance_hdr", "rle.hdr", read(scratch / "rle.hdr"));
  write_radiance_hdr(scratch / "flat.hdr", pattern(5, 2), false);
  write("fuzz_radiance_hdr", "flat.hdr", read(scratch / "flat.hdr"));
  // Old-style run lengths (a 1,1,1 pixel repeats the previous one), another orientation, EXPOSURE.
  std::string old = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\nEXPOSURE=2\n\n+Y 1 -X 4\n";
  for (const uint8_t b : {128, 64, 32, 129, 1, 1, 1, 2, 10, 20, 30, 130}) old += char(b);
  write("fuzz_radiance_hdr", "old-rle.hdr", old);

  write_openexr(scratch / "half.exr", pattern(4, 3));
  write("fuzz_openexr", "half-zip.exr", read(scratch / "half.exr"));
  std::vector<Imf::Rgba> pixels(6, Imf::Rgba(0.5f, 0.25f, 1.0f, 1.0f));
  {
    Imf::RgbaOutputFile luminance((scratch / "y.exr").c_str(), 3, 2, Imf::WRITE_Y, 1, Imath::V2f(0, 0), 1,
                                  Imf::INCREASING_Y, Imf::NO_COMPRESSION);
    luminance.setFrameBuffer(pixels.data(), 1, 3);
    luminance.writePixels(2);
  }
  write("fuzz_openexr", "luminance.exr", read(scratch / "y.exr"));
  {
    Imf::TiledRgbaOutputFile tiled((scratch / "tiled.exr").c_str(), 3, 2, 2, 2, Imf::ONE_LEVEL, Imf::ROUND_DOWN,
                                   Imf::WRITE_RGBA, 1, Imath::V2f(0, 0), 1, Imf::INCREASING_Y, Imf::RLE_COMPRESSION);
    tiled.setFrameBuffer(pixels.data(), 1, 3);
    tiled.writeTiles(0, tiled.numXTiles() - 1, 0, tiled.numYTiles() - 1);
  }
  write("fuzz_openexr", "tiled-rle.exr", read(scratch / "tiled.exr"));
  // The sky loader of the simulator reads .hdr files too (through OpenCV).
  write("fuzz_openexr", "rle.hdr", read(scratch / "rle.hdr"));
}

void image_seeds(const fs::path& scratch) {
  cv::Mat colour(6, 8, CV_8UC3), grey(5, 7, CV_8UC1), deep(3, 4, CV_16UC3);
  for (int i = 0; i < colour.rows * colour.cols * 3; ++i) colour.data[i] = uint8_t(i * 37);
  for (int i = 0; i < grey.rows * grey.cols; ++i) grey.data[i] = uint8_t(i * 11);
  deep.setTo(cv::Scalar(1000, 20000, 65535));
  const auto save = [&](const std::string& name, const cv::Mat& image, const std::vector<int>& params) {
    cv::imwrite((scratch / name).string(), image, params);
    write("fuzz_png_jpeg", name, read(scratch / name));
  };
  save("colour.png", colour, {});
  save("grey.png", grey, {});
  save("deep.png", deep, {});
  save("baseline.jpg", colour, {cv::IMWRITE_JPEG_QUALITY, 80});
  save("progressive.jpg", colour, {cv::IMWRITE_JPEG_PROGRESSIVE, 1});
  save("grey.jpg", grey, {});
}

void camera_model_seeds() {
  const auto save = [](const std::string& name, const CameraModel& model) {
    write("fuzz_cameramodel", name, model.to_string());
  };
  save("pinhole.cameramodel", CameraModel::pinhole(500, 500, 319.5, 239.5, 640, 480));
  save("opencv4.cameramodel", CameraModel("LENSMODEL_OPENCV4", {500, 510, 320, 240, -0.1, 0.01, 1e-4, -1e-4}, 640, 480));
  save("opencv8.cameramodel",
       CameraModel("LENSMODEL_OPENCV8", {500, 510, 320, 240, -0.1, 0.01, 1e-4, -1e-4, 1e-3, 0, 0, 0}, 640, 480));
  save("stereographic.cameramodel", CameraModel("LENSMODEL_STEREOGRAPHIC", {300, 300, 320, 240}, 640, 480));
  save("cahvor.cameramodel", CameraModel("LENSMODEL_CAHVOR", {500, 500, 320, 240, 0.01, 0.02, 0.001, 0.002, 0.003}, 640, 480));
  std::vector<double> splined = {300, 300, 320, 240};
  splined.resize(4 + 2 * 4 * 4, 0.001);
  save("splined.cameramodel",
       CameraModel("LENSMODEL_SPLINED_STEREOGRAPHIC_order=3_Nx=4_Ny=4_fov_x_deg=100", splined, 640, 480));
}

// A recording as fuzz_recording reads it: its files joined by the target's separator line.
void recording_seeds(const fs::path& scratch) {
  const std::string separator = "\n--arpipe-fuzz-part--\n";
  for (const bool truth : {false, true}) {
    const fs::path dir = scratch / (truth ? "rec-truth" : "rec");
    RecordingInfo info;
    info.pixel_format = truth ? PixelFormat::GREY : PixelFormat::YUYV;
    info.width = 4;
    info.height = 2;
    info.source = "fuzz seed";
    info.created_utc = "2024-05-01T12:00:00Z";
    {
      RecordingWriter writer(dir, info, CameraModel::pinhole(4, 4, 1.5, 0.5, 4, 2));
      for (int i = 0; i < 2; ++i) {
        Frame frame = Frame::allocate(info.pixel_format, info.width, info.height);
        for (size_t b = 0; b < frame.data.size(); ++b) frame.data[b] = uint8_t(b * 7 + i);
        frame.meta.sequence = uint64_t(i);
        frame.meta.exposure_start_ns = 1'000'000'000 + i * 33'333'333;
        frame.meta.exposure_ns = 4'000'000;
        frame.meta.frame_duration_ns = 33'333'333;
        frame.meta.lux = truth ? 0 : 120.5;
        std::optional<GroundTruthFrame> gt;
        if (truth) {
          gt.emplace();
          gt->sequence = uint64_t(i);
          gt->rows = {{0, SE3{}}, {1, SE3{}}};
          gt->lights = {GroundTruthLight{"sun", "directional", {0, 0, 1}, {0, 0, 0}, {1, 1, 1}, 100, 0.01, 0}};
          gt->sun = GroundTruthSun{1.0, 0.5};
          gt->exposure_ns = 4'000'000;
        }
        writer.append(frame, gt);
      }
    }
    std::string joined = read(dir / "recording.json") + separator + read(dir / "camera.cameramodel") + separator +
                         read(dir / "frames.jsonl") + separator;
    if (truth) joined += read(dir / "ground_truth.jsonl");
    joined += separator + read(dir / "frames.bin");
    write("fuzz_recording", truth ? "grey-ground-truth.rec" : "yuyv.rec", joined);
  }
}

void prt_seeds(const fs::path& scratch) {
  for (const int bands : {1, 3}) {
    PrtTransfer transfer;
    transfer.bands = bands;
    transfer.samples_per_axis = 8;
    transfer.coefficients.assign(size_t(3 * bands * bands), 0.25f);
    const std::string key = "0123456789abcdef0123456789abcdef";
    write_prt_cache(scratch / "cache.prt", key, transfer);
    write("fuzz_prt_cache", "bands" + std::to_string(bands) + ".prt", read(scratch / "cache.prt"));
  }
}

void config_seeds() {
  write("fuzz_config", "defaults.toml", default_config_toml());
  // Whole inputs are also tried as one `--set` override (fuzz_config.cpp).
  write("fuzz_config", "set-index", "render.objects.0.scale=2");
  write("fuzz_config", "set-word", "source.pacing=fast");
  write("fuzz_config", "set-table", "track.bundle=[{id = 3, size_m = 0.05}]");
  write("fuzz_config", "set-int", "source.timestamp_offset_ns=-5");
}

}  // namespace

// fuzz_board_detection: each of its boards drawn by `arpipe board`'s writer, shrunk to 96 pixels
// across with a 12-pixel white border, as the target's input (detected through a lens too).
void board_detection_seeds(const fs::path& scratch) {
  for (size_t which = 0; which < std::size(fuzz::kDetectionBoards); ++which) {
    const calib::CalibrationBoard board = calib::parse_board(fuzz::kDetectionBoards[which], "seed.toml");
    const fs::path png = scratch / ("board-" + std::to_string(which) + ".png");
    calib::write_board_png(board, png, 100);
    const cv::Mat drawn = cv::imread(png.string(), cv::IMREAD_GRAYSCALE);
    const double scale = 96.0 / std::max(drawn.cols, drawn.rows);
    cv::Mat shrunk, small;
    cv::resize(drawn, shrunk, cv::Size(), scale, scale, cv::INTER_AREA);
    cv::copyMakeBorder(shrunk, small, 12, 12, 12, 12, cv::BORDER_CONSTANT, cv::Scalar(255));  // a quiet zone
    std::vector<unsigned char> grey;
    for (int y = 0; y < small.rows; ++y) grey.insert(grey.end(), small.ptr<unsigned char>(y), small.ptr<unsigned char>(y) + small.cols);
    write("fuzz_board_detection", "board-" + std::to_string(which),
          fuzz::encode_detection_input(which, small.cols, small.rows, true, grey));
  }
}

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: fuzz_make_seeds OUT_DIR\n");
    return 2;
  }
  out_root = argv[1];
  const fs::path scratch = out_root / ".scratch";
  fs::remove_all(scratch);
  fs::create_directories(scratch);
  gltf_seeds();
  hdr_seeds(scratch);
  image_seeds(scratch);
  camera_model_seeds();
  recording_seeds(scratch);
  prt_seeds(scratch);
  config_seeds();
  board_detection_seeds(scratch);
  fs::remove_all(scratch);
  return 0;
}
