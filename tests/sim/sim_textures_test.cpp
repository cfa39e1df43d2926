// Plane textures and the sky map against the tag family's own bit layout, the chessboard rule,
// sRGB decoding and the equirectangular mapping of sim_scene.h.
#include "capture/sim/sim_textures.h"
#include "core/image/srgb.h"

#include <apriltag/apriltag.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <fstream>
#include <functional>
#include <numbers>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>

#include "core/scene/asset_error.h"
#include "core/track/tag_family.h"
#include "tests/sim/sim_test_support.h"

namespace arpipe::sim {
namespace {

namespace fs = std::filesystem;
constexpr double kPi = std::numbers::pi;

fs::path temp_dir(const std::string& name) {
  const fs::path dir =
      fs::path(::testing::TempDir()) / ("arpipe_sim_textures_" + name + "_" + std::to_string(getpid()));
  fs::create_directories(dir);
  return dir;
}

std::string expect_asset_error(const std::function<void()>& fn) {
  try {
    fn();
  } catch (const AssetError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no AssetError";
  return {};
}

SimMaterial tag_material(const std::string& family, int id) {
  SimMaterial m;
  m.texture.kind = SimTexture::Kind::AprilTag;
  m.texture.family = family;
  m.texture.tag_id = id;
  m.texture.dark = {0.03, 0.04, 0.05};
  m.texture.light = {0.8, 0.7, 0.6};
  return m;
}

TEST(SimTexture, SrgbDecodingMatchesTheStandard) {
  EXPECT_EQ(srgb_decode(0.0), 0.0);
  EXPECT_NEAR(srgb_decode(1.0), 1.0, 1e-15);
  EXPECT_NEAR(srgb_decode(0.04045), 0.04045 / 12.92, 1e-15);  // the linear segment's end
  EXPECT_NEAR(srgb_decode(0.5), 0.214041140, 1e-9);           // IEC 61966-2-1 reference value
  EXPECT_NEAR(srgb_decode(128 / 255.0), 0.215860500, 1e-9);
}

// The printed cells of a tag, 1 = paper, row 0 on top, from the family's documented layout
// (AprilTag 3): a one-cell paper ring of side width_at_border (+2 unless the border is reversed),
// centred; then the code's bits, most significant first, at (bit_x, bit_y) from the border's corner.
std::vector<int> expected_cells(const apriltag_family& f, int id) {
  const int n = f.total_width;
  std::vector<int> white(size_t(n) * n, 0);
  const int ring = f.width_at_border + (f.reversed_border ? 0 : 2);
  const int ring_start = (n - ring) / 2;
  for (int row = ring_start; row < ring_start + ring; ++row)
    for (int col = ring_start; col < ring_start + ring; ++col)
      if (row == ring_start || col == ring_start || row == ring_start + ring - 1 || col == ring_start + ring - 1)
        white[size_t(row * n + col)] = 1;
  const int border_start = (n - f.width_at_border) / 2;
  for (uint32_t i = 0; i < f.nbits; ++i)
    if ((f.codes[id] >> (f.nbits - 1 - i)) & 1u)
      white[size_t((int(f.bit_y[i]) + border_start) * n + int(f.bit_x[i]) + border_start)] = 1;
  return white;
}

TEST(SimTexture, AprilTagCellsFollowTheFamilyBitLayout) {
  // tag36h11: classic layout (paper ring outside the black border); tagStandard41h12: reversed
  // border with data outside it; tagCircle21h7: a round family with its corners unused.
  for (const auto& [name, id] : {std::pair{"tag36h11", 17}, {"tagStandard41h12", 3}, {"tagCircle21h7", 30}}) {
    const PlaneTexture texture(tag_material(name, id), "tag");
    const TagFamilyPtr family = create_tag_family(name);
    const int n = family->total_width;
    const std::vector<int> white = expected_cells(*family, id);
    int paper = 0;
    for (int row = 0; row < n; ++row)
      for (int col = 0; col < n; ++col) {
        const Rgb expected = white[size_t(row * n + col)] ? Rgb{0.8, 0.7, 0.6} : Rgb{0.03, 0.04, 0.05};
        paper += white[size_t(row * n + col)];
        // Anywhere inside the cell (nearest texel): its centre and just inside its corners.
        for (double du : {0.5, 1e-9, 1 - 1e-9})
          for (double dv : {0.5, 1e-9, 1 - 1e-9})
            EXPECT_EQ(texture.reflectance((col + du) / n, (row + dv) / n), expected)
                << name << " " << row << " " << col;
      }
    // Neither all ink nor all paper: the pattern really came through.
    EXPECT_GT(paper, n) << name;
    EXPECT_LT(paper, n * n - n) << name;
  }
}

TEST(SimTexture, ChessboardTopLeftSquareIsDark) {
  SimMaterial m;
  m.texture.kind = SimTexture::Kind::Chessboard;
  m.texture.rows = 3;
  m.texture.cols = 4;
  m.texture.margin_squares = 0.5;
  const PlaneTexture texture(m, "board");
  const Rgb dark = m.texture.dark, light = m.texture.light;
  // The plane spans 5 x 4 squares: u = (col + 0.5 + x) / 5, v = (row + 0.5 + y) / 4.
  for (int row = 0; row < 3; ++row)
    for (int col = 0; col < 4; ++col) {
      const Rgb expected = (row + col) % 2 == 0 ? dark : light;
      EXPECT_EQ(texture.reflectance((col + 1.0) / 5, (row + 1.0) / 4), expected);
      EXPECT_EQ(texture.reflectance((col + 0.5 + 1e-9) / 5, (row + 0.5 + 1e-9) / 4), expected);
      EXPECT_EQ(texture.reflectance((col + 1.5 - 1e-9) / 5, (row + 1.5 - 1e-9) / 4), expected);
    }
  // The margin is paper.
  EXPECT_EQ(texture.reflectance(0.05, 0.5), light);
  EXPECT_EQ(texture.reflectance(0.5, 0.99), light);
  EXPECT_EQ(texture.reflectance(0.5 / 5 - 1e-9, 1.0 / 4), light);
}

TEST(SimTexture, ImageIsDecodedFromSrgbAndSampledBilinearly) {
  const fs::path dir = temp_dir("image");
  // 3 x 2 pixels, OpenCV's BGR order; the top-left pixel is red.
  cv::Mat image(2, 3, CV_8UC3);
  image.at<cv::Vec3b>(0, 0) = {0, 0, 255};
  image.at<cv::Vec3b>(0, 1) = {0, 255, 0};
  image.at<cv::Vec3b>(0, 2) = {255, 0, 0};
  image.at<cv::Vec3b>(1, 0) = {128, 128, 128};
  image.at<cv::Vec3b>(1, 1) = {10, 60, 200};
  image.at<cv::Vec3b>(1, 2) = {255, 255, 255};
  const fs::path path = dir / "tex.png";
  ASSERT_TRUE(cv::imwrite(path.string(), image));
  SimMaterial m;
  m.albedo = {0.5, 0.8, 1.0};
  m.texture.kind = SimTexture::Kind::Image;
  m.texture.image_path = path;
  const PlaneTexture texture(m, "poster");
  auto linear = [&](int row, int col) {
    const cv::Vec3b bgr = image.at<cv::Vec3b>(row, col);
    return Rgb{0.5 * srgb_decode(bgr[2] / 255.0), 0.8 * srgb_decode(bgr[1] / 255.0),
               1.0 * srgb_decode(bgr[0] / 255.0)};
  };
  // Texel centres are exact (to float storage, 1e-7); the corners clamp to the corner texels.
  auto expect_rgb = [](const Rgb& got, const Rgb& want) {
    for (size_t c = 0; c < 3; ++c) EXPECT_NEAR(got[c], want[c], 1e-7);
  };
  for (int row = 0; row < 2; ++row)
    for (int col = 0; col < 3; ++col)
      expect_rgb(texture.reflectance((col + 0.5) / 3, (row + 0.5) / 2), linear(row, col));
  expect_rgb(texture.reflectance(0, 0), linear(0, 0));
  expect_rgb(texture.reflectance(1, 1), linear(1, 2));
  // Halfway between the centres of (0,0) and (0,1), and the centre of the four left texels.
  Rgb a = linear(0, 0), b = linear(0, 1), c = linear(1, 0), d = linear(1, 1);
  expect_rgb(texture.reflectance(1.0 / 3, 0.25), {(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2});
  expect_rgb(texture.reflectance(1.0 / 3, 0.5),
             {(a[0] + b[0] + c[0] + d[0]) / 4, (a[1] + b[1] + c[1] + d[1]) / 4, (a[2] + b[2] + c[2] + d[2]) / 4});
}

TEST(SimTexture, MissingOrBrokenImageNamesTheFile) {
  const fs::path dir = temp_dir("broken");
  SimMaterial m;
  m.texture.kind = SimTexture::Kind::Image;
  m.texture.image_path = dir / "nowhere.png";
  std::string message = expect_asset_error([&] { PlaneTexture(m, "poster"); });
  EXPECT_NE(message.find("nowhere.png"), std::string::npos) << message;
  EXPECT_NE(message.find("poster"), std::string::npos) << message;
  std::ofstream(dir / "text.png") << "not an image";
  m.texture.image_path = dir / "text.png";
  message = expect_asset_error([&] { PlaneTexture(m, "poster"); });
  EXPECT_NE(message.find("text.png"), std::string::npos) << message;
}

TEST(SimTexture, BadTagOrBoardNamesTheObject) {
  auto message = [](const SimMaterial& m) {
    try {
      PlaneTexture texture(m, "thing7");
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no exception");
  };
  EXPECT_NE(message(tag_material("tag99h99", 0)).find("thing7"), std::string::npos);
  EXPECT_NE(message(tag_material("tag99h99", 0)).find("tag99h99"), std::string::npos);
  EXPECT_NE(message(tag_material("tag36h11", 587)).find("587"), std::string::npos);  // 587 codes: 0..586
  EXPECT_NE(message(tag_material("tag36h11", -1)).find("thing7"), std::string::npos);
  SimMaterial board;
  board.texture.kind = SimTexture::Kind::Chessboard;
  board.texture.rows = 0;
  board.texture.cols = 5;
  EXPECT_NE(message(board).find("thing7"), std::string::npos);
}

TEST(SimTexture, EquirectangularMappingFollowsSimScene) {
  // u = atan2(y, x) / 2 pi wrapped to [0, 1), v = acos(z) / pi: +z is the top row.
  auto uv = [](const Vec3& d, double rotation = 0) { return equirect_uv(normalized(d), rotation); };
  EXPECT_NEAR(uv({1, 0, 0})[0], 0.0, 1e-15);
  EXPECT_NEAR(uv({0, 1, 0})[0], 0.25, 1e-15);
  EXPECT_NEAR(uv({-1, 0, 0})[0], 0.5, 1e-15);
  EXPECT_NEAR(uv({0, -1, 0})[0], 0.75, 1e-15);
  EXPECT_NEAR(uv({1, 0, 0})[1], 0.5, 1e-15);
  EXPECT_NEAR(uv({0, 0, 1})[1], 0.0, 1e-15);
  EXPECT_NEAR(uv({0, 0, -1})[1], 1.0, 1e-15);
  EXPECT_NEAR(uv({1, 0, 1})[1], 0.25, 1e-15);
  EXPECT_NEAR(uv({0, 1, 0}, kPi / 2)[0], 0.5, 1e-15);  // rotation turns the image about +z
  EXPECT_NEAR(uv({0, -1, 0}, kPi / 2)[0], 0.0, 1e-15);
  const double u = uv({1, -1e-300, 0})[0];
  EXPECT_GE(u, 0.0);
  EXPECT_LT(u, 1.0);
}


Vec3 direction_at(double u, double v, double rotation = 0) {
  const double phi = 2 * kPi * u - rotation, theta = kPi * v;
  return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}

TEST(SimTexture, HdrSkyIsBilinearAndWrapsInU) {
  const fs::path path = temp_dir("sky") / "sky.hdr";
  const std::vector<Rgb> pixels = test::write_test_sky(path);
  SimEnvironment env;
  env.hdr_path = path;
  env.radiance = {2, 1, 0.5};
  const EnvironmentMap map(env);
  EXPECT_FALSE(map.is_black());
  auto near = [](const Rgb& got, const Rgb& want) {
    // The direction round trip costs ~1e-15 of bilinear weight; float storage 1e-7 relative.
    for (size_t c = 0; c < 3; ++c) EXPECT_NEAR(got[c], want[c], 1e-6 * (1 + want[c]));
  };
  auto pixel = [&](int row, int col) {
    const Rgb& p = pixels[size_t(row * 8 + col)];
    return Rgb{2 * p[0], p[1], 0.5 * p[2]};
  };
  for (int row = 0; row < 4; ++row)
    for (int col = 0; col < 8; ++col)
      near(map.radiance(direction_at((col + 0.5) / 8, (row + 0.5) / 4)), pixel(row, col));
  // u = 0 lies halfway between the last and the first column.
  const Rgb a = pixel(1, 7), b = pixel(1, 0);
  near(map.radiance(direction_at(0, 1.5 / 4)), {(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2});
  // Above the top row's centres v clamps to that row.
  near(map.radiance(direction_at((2 + 0.5) / 8, 0.01)), pixel(0, 2));

  // Rotating by one column's width moves every pixel one column along.
  env.rotation_rad = 2 * kPi / 8;
  const EnvironmentMap rotated(env);
  near(rotated.radiance(direction_at(3.5 / 8, 2.5 / 4, env.rotation_rad)), pixel(2, 3));
  near(rotated.radiance(direction_at(3.5 / 8, 2.5 / 4)), pixel(2, 4));
}

TEST(SimTexture, ConstantSky) {
  SimEnvironment env;
  EXPECT_TRUE(EnvironmentMap(env).is_black());
  env.radiance = {0.1, 0.2, 0.3};
  const EnvironmentMap map(env);
  EXPECT_FALSE(map.is_black());
  EXPECT_EQ(map.radiance(normalized(Vec3{0.3, -0.4, -0.1})), env.radiance);
}

TEST(SimTexture, BadHdrNamesTheFile) {
  const fs::path dir = temp_dir("badsky");
  SimEnvironment env;
  env.hdr_path = dir / "missing.hdr";
  std::string message = expect_asset_error([&] { EnvironmentMap map(env); });
  EXPECT_NE(message.find("missing.hdr"), std::string::npos) << message;
  // An 8-bit image is not radiance.
  cv::Mat ldr(2, 4, CV_8UC3, cv::Scalar(10, 20, 30));
  ASSERT_TRUE(cv::imwrite((dir / "ldr.png").string(), ldr));
  env.hdr_path = dir / "ldr.png";
  message = expect_asset_error([&] { EnvironmentMap map(env); });
  EXPECT_NE(message.find("ldr.png"), std::string::npos) << message;
  EXPECT_NE(message.find("expected a Radiance .hdr or OpenEXR .exr file"), std::string::npos) << message;
  std::ofstream(dir / "garbage.hdr") << "#?RADIANCE\nnonsense";
  env.hdr_path = dir / "garbage.hdr";
  message = expect_asset_error([&] { EnvironmentMap map(env); });
  EXPECT_NE(message.find("garbage.hdr"), std::string::npos) << message;
}

}  // namespace
}  // namespace arpipe::sim
