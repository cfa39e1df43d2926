// The simulator's real-photo effects against analytic results: defocus (a disc PSF: its step
// response is the disc's edge-spread function), vignetting (cos^4 of the field angle), JPEG (the
// same bytes as libjpeg-turbo's own round trip, and a sane PSNR), the Blinn-Phong highlight (at
// the mirror point, of the normalised lobe's height), the defaults changing nothing, and the
// scene keys' range errors naming file, line and key.
#include <gtest/gtest.h>
#include <turbojpeg.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>

#include "capture/recording/recording_reader.h"
#include "capture/sim/jpeg_round_trip.h"
#include "capture/sim/lens_optics.h"
#include "capture/sim/scene_shader.h"
#include "capture/sim/sim_scene_loader.h"
#include "capture/sim/simulator.h"
#include "core/image/pixel_convert.h"
#include "tests/sim/sim_test_support.h"

namespace arpipe::sim {
namespace {

using namespace arpipe::sim::test;

constexpr double kPi = 3.14159265358979323846;

// The fraction of a disc of radius r lying at x > -s (its edge-spread function).
double disc_esf(double s, double r) {
  if (s <= -r) return 0;
  if (s >= r) return 1;
  return 0.5 + (s * std::sqrt(r * r - s * s) + r * r * std::asin(s / r)) / (kPi * r * r);
}

RadianceImage grey_image(int width, int height, float value) {
  RadianceImage image;
  image.width = width;
  image.height = height;
  image.rgb.assign(size_t(width) * height * 3, value);
  return image;
}

// ---- Defocus -----------------------------------------------------------------------------------

TEST(SimDefocus, DiscKernelSumsToOneAndIsSymmetric) {
  for (const double diameter : {0.0, 0.8, 1.0, 1.2, 1.5, 3.0, 7.3, 32.0}) {
    const DiscKernel kernel = disc_kernel(diameter);
    // Taps reach |k| - 1/2 < r: the smallest square holding the disc.
    EXPECT_EQ(kernel.half_size, diameter <= 1 ? 0 : int(std::ceil(diameter / 2 - 0.5))) << diameter;
    double sum = 0;
    for (const double w : kernel.weights) sum += w;
    EXPECT_NEAR(sum, 1.0, 1e-12) << diameter;
    for (int j = -kernel.half_size; j <= kernel.half_size; ++j)
      for (int i = -kernel.half_size; i <= kernel.half_size; ++i) {
        EXPECT_NEAR(kernel.at(i, j), kernel.at(-i, j), 1e-12);
        EXPECT_NEAR(kernel.at(i, j), kernel.at(j, i), 1e-12);
      }
  }
  EXPECT_EQ(disc_kernel(1.0).weights, std::vector<double>{1.0});  // a disc inside the pixel: in focus
  // Diameter 3: the centre pixel lies wholly in the disc (its corners 0.71 px out): 1 / (pi r^2).
  // Tap (1, 0) holds the disc in [0.5, 1.5] x [-0.5, 0.5]: the full 1 px height out to x = sqrt 2
  // (where the chord is 1 px long), then the chord 2 h(x) = 2 sqrt(r^2 - x^2) out to r.
  const DiscKernel three = disc_kernel(3.0);
  const double r = 1.5, disc = kPi * r * r;
  const auto chord_integral = [&](double x) { return 0.5 * (x * std::sqrt(std::max(0.0, r * r - x * x)) + r * r * std::asin(x / r)); };
  EXPECT_NEAR(three.at(0, 0), 1 / disc, 1e-14);
  EXPECT_NEAR(three.at(1, 0), ((std::sqrt(2.0) - 0.5) + 2 * (chord_integral(1.5) - chord_integral(std::sqrt(2.0)))) / disc,
              1e-14);
  EXPECT_THROW(disc_kernel(-1), std::invalid_argument);
}

// A vertical step between columns 19 and 20 (at x = 19.5): column c of the blurred image holds the
// share of the disc beyond the step, the disc's edge-spread function at c - 19.5, exactly (to
// float rounding, 1e-6): so the blur has the disc's radius, and only the columns within the
// radius of the step change.
TEST(SimDefocus, StepEdgeProfileIsTheDiscsEdgeSpreadFunction) {
  for (const double diameter : {1.5, 3.0, 6.4}) {
    const double r = diameter / 2;
    RadianceImage image = grey_image(40, 9, 0.0f);
    for (int y = 0; y < 9; ++y)
      for (int x = 20; x < 40; ++x)
        for (int c = 0; c < 3; ++c) image.rgb[(size_t(y) * 40 + x) * 3 + c] = 1.0f;
    apply_defocus(disc_kernel(diameter), image);
    int changed = 0;
    for (int x = 0; x < 40; ++x) {
      const double expected = disc_esf(x - 19.5, r);
      const float got = image.rgb[(size_t(4) * 40 + x) * 3 + 1];
      EXPECT_NEAR(got, expected, 1e-6) << "diameter " << diameter << " column " << x;
      if (got > 1e-7 && got < 1 - 1e-7) ++changed;
    }
    // Columns c with |c - 19.5| < r: 2 ceil(r - 1/2) of them.
    EXPECT_EQ(changed, 2 * int(std::ceil(r - 0.5))) << diameter;
  }
}

TEST(SimDefocus, KeepsFluxAndUniformImages) {
  RadianceImage point = grey_image(31, 31, 0.0f);
  for (int c = 0; c < 3; ++c) point.rgb[(15 * 31 + 15) * 3 + c] = 1.0f;
  apply_defocus(disc_kernel(5.0), point);
  double sum = 0;
  for (size_t p = 0; p < point.rgb.size(); p += 3) sum += point.rgb[p];
  EXPECT_NEAR(sum, 1.0, 1e-6);
  // The blurred point is the kernel itself.
  EXPECT_NEAR(point.rgb[(15 * 31 + 17) * 3], disc_kernel(5.0).at(2, 0), 1e-7);
  // Edges are clamped: a uniform image stays uniform to float rounding, corners included.
  RadianceImage flat = grey_image(12, 10, 0.37f);
  apply_defocus(disc_kernel(9.0), flat);
  for (const float v : flat.rgb) EXPECT_NEAR(v, 0.37f, 1e-6f);
}

// ---- Vignetting --------------------------------------------------------------------------------

TEST(SimVignetting, RelativeIlluminationIsCosFourthOfTheFieldAngle) {
  EXPECT_DOUBLE_EQ(relative_illumination(1.0, 1.0), 1.0);
  EXPECT_NEAR(relative_illumination(std::cos(kPi / 4), 1.0), 0.25, 1e-15);
  EXPECT_NEAR(relative_illumination(std::cos(kPi / 3), 1.0), 1.0 / 16, 1e-15);
  EXPECT_NEAR(relative_illumination(std::cos(kPi / 4), 0.6), 0.4 + 0.6 * 0.25, 1e-15);
  EXPECT_DOUBLE_EQ(relative_illumination(-0.5, 1.0), 0.0);  // behind the lens plane: no light
  EXPECT_DOUBLE_EQ(relative_illumination(0.3, 0.0), 1.0);
}

// A pinhole f = 100 px, centre (200, 100): pixel (300, 100) sees 45 degrees off axis (cos^4 =
// 1/4), pixel (300, 200) tan = sqrt 2 (cos^2 = 1/3, cos^4 = 1/9); the ray grid is within 0.002 px,
// 2e-5 in cos^4 at most here.
TEST(SimVignetting, LensOpticsFollowsTheRaysOfAPinhole) {
  const CameraModel model = CameraModel::pinhole(100, 100, 200, 100, 401, 201);
  const CameraRayGrid rays(model);
  SimOptics optics;
  optics.vignetting = 0.8;
  const LensOptics lens(optics, rays, 401, 201);
  const auto at = [&](int x, int y) { return lens.illumination()[size_t(y) * 401 + size_t(x)]; };
  EXPECT_NEAR(at(200, 100), 1.0, 1e-6);
  EXPECT_NEAR(at(300, 100), 0.2 + 0.8 / 4, 2e-5);
  EXPECT_NEAR(at(100, 100), 0.2 + 0.8 / 4, 2e-5);
  EXPECT_NEAR(at(300, 200), 0.2 + 0.8 / 9, 2e-5);
  EXPECT_NEAR(at(200, 0), 0.2 + 0.8 / 4, 2e-5);
  RadianceImage image = grey_image(401, 201, 2.0f);
  lens.apply(image);
  EXPECT_NEAR(image.rgb[(size_t(200) * 401 + 300) * 3 + 2], 2.0 * (0.2 + 0.8 / 9), 4e-5);
}

// End to end: a camera that sees only a uniform sky writes the sky's linear value times the
// relative illumination into its noise-free linear image, and defocus leaves a uniform image alone.
TEST(SimVignetting, SimulatedUniformSkyFallsOffAsCosFourth) {
  SimScene scene;
  scene.camera = exact_camera(81, 41, 40);  // centre (40, 20): column 80 is 45 degrees off axis
  scene.camera.optics.vignetting = 1.0;
  scene.camera.optics.defocus_px = 2.5;
  scene.environment.radiance = {1.0, 1.0, 1.0};  // 4 ms x 100: 0.4 of full scale
  scene.trajectory = still({0, 0, 1}, {0, 0, 0});
  scene.render.samples_per_pixel = 1;
  scene.render.write_linear = true;
  const fs::path dir = scratch_dir("vignetting");
  SimulateOptions options;
  options.out_dir = dir;
  options.frames = 1;
  simulate(scene, options);
  const cv::Mat linear = read_linear(dir / "linear_000000.pfm");
  ASSERT_EQ(linear.cols, 81);
  EXPECT_NEAR(linear.at<cv::Vec3f>(20, 40)[1], 0.4, 1e-6);
  EXPECT_NEAR(linear.at<cv::Vec3f>(20, 80)[1], 0.4 * 0.25, 1e-5);
  EXPECT_NEAR(linear.at<cv::Vec3f>(40, 80)[0], 0.4 / std::pow(1 + 0.25 + 1, 2), 1e-5);  // tan^2 = 1/4 + 1
  fs::remove_all(dir);
}

// ---- JPEG --------------------------------------------------------------------------------------

// A test picture with edges, gradients and fine texture: a chessboard of 8 px squares under a
// colour ramp, plus a deterministic grey pattern of +-12 codes (luma detail: 4:2:0 keeps it).
std::vector<uint8_t> test_picture(int width, int height) {
  std::vector<uint8_t> rgb(size_t(width) * height * 3);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const bool dark = ((x / 8) + (y / 8)) % 2 == 0;
      const int texture = int((x * 7919u + y * 104729u) % 25u) - 12;
      const int base = dark ? 40 : 200;
      const int values[3] = {base + x * 30 / width + texture, base + texture, base + y * 30 / height + texture};
      for (int c = 0; c < 3; ++c) rgb[(size_t(y) * width + x) * 3 + c] = uint8_t(std::clamp(values[c], 0, 255));
    }
  return rgb;
}

double psnr(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b) {
  double sum = 0;
  for (size_t i = 0; i < a.size(); ++i) sum += (double(a[i]) - b[i]) * (double(a[i]) - b[i]);
  return 10 * std::log10(255.0 * 255.0 / (sum / double(a.size())));
}

// libjpeg-turbo's own round trip of the same pixels: RGB 4:2:0 (grey: one component), accurate DCT.
std::vector<uint8_t> reference_round_trip(const std::vector<uint8_t>& pixels, int width, int height, int channels,
                                          int quality) {
  const std::unique_ptr<void, int (*)(tjhandle)> encoder(tjInitCompress(), tjDestroy), decoder(tjInitDecompress(), tjDestroy);
  unsigned char* jpeg = nullptr;
  unsigned long size = 0;
  EXPECT_EQ(tjCompress2(encoder.get(), pixels.data(), width, 0, height, channels == 3 ? TJPF_RGB : TJPF_GRAY, &jpeg,
                        &size, channels == 3 ? TJSAMP_420 : TJSAMP_GRAY, quality, TJFLAG_ACCURATEDCT),
            0);
  std::vector<uint8_t> out(pixels.size());
  EXPECT_EQ(tjDecompress2(decoder.get(), jpeg, size, out.data(), width, 0, height, channels == 3 ? TJPF_RGB : TJPF_GRAY,
                          TJFLAG_ACCURATEDCT),
            0);
  tjFree(jpeg);
  return out;
}

TEST(SimJpeg, RoundTripIsLibjpegTurbosAndLossyWithinReason) {
  const int width = 96, height = 64;
  const std::vector<uint8_t> original = test_picture(width, height);
  double previous_psnr = 0;
  for (const int quality : {30, 75, 95}) {
    std::vector<uint8_t> pixels = original;
    jpeg_round_trip(pixels.data(), width, height, size_t(width) * 3, 3, quality);
    EXPECT_EQ(pixels, reference_round_trip(original, width, height, 3, quality)) << quality;
    const double db = psnr(original, pixels);
    std::printf("JPEG quality %d: PSNR %.2f dB\n", quality, db);
    // JPEG of an 8-bit picture with texture: well short of lossless, far from garbage, and
    // better at a higher quality.
    EXPECT_GT(db, 24.0) << quality;
    EXPECT_LT(db, 48.0) << quality;
    EXPECT_GT(db, previous_psnr) << quality;
    previous_psnr = db;
  }
  std::vector<uint8_t> grey(size_t(width) * height);
  for (size_t p = 0; p < grey.size(); ++p) grey[p] = original[p * 3 + 1];
  std::vector<uint8_t> grey_jpeg = grey;
  jpeg_round_trip(grey_jpeg.data(), width, height, size_t(width), 1, 75);
  EXPECT_EQ(grey_jpeg, reference_round_trip(grey, width, height, 1, 75));
  EXPECT_NE(grey_jpeg, grey);
  EXPECT_THROW(jpeg_round_trip(grey.data(), width, height, size_t(width), 1, 0), std::invalid_argument);
  EXPECT_THROW(jpeg_round_trip(grey.data(), width, height, size_t(width), 2, 75), std::invalid_argument);
}

// A small textured scene, simulated into dir.
SimScene board_scene(PixelFormat format, int jpeg_quality) {
  SimScene scene;
  scene.camera = exact_camera(96, 64, 80);
  scene.camera.pixel_format = format;
  scene.camera.sensor.response = CameraResponse::srgb();
  scene.camera.sensor.sensitivity = 800;
  scene.camera.jpeg_quality = jpeg_quality;
  SimTexture board;
  board.kind = SimTexture::Kind::Chessboard;
  board.rows = 5;
  board.cols = 7;
  board.margin_squares = 1;
  scene.objects.push_back(ground_plane("board", 9 * 0.02, 7 * 0.02, board));
  scene.lights.push_back(overhead_sun(kPi));
  scene.trajectory = still({0.01, -0.05, 0.25}, {0, 0, 0});
  scene.render.samples_per_pixel = 4;
  return scene;
}

Frame simulate_one(const SimScene& scene, const std::string& name) {
  const fs::path dir = scratch_dir(name);
  SimulateOptions options;
  options.out_dir = dir;
  options.frames = 1;
  options.threads = 2;
  simulate(scene, options);
  Frame frame;
  RecordingReader(dir).read(0, frame);
  fs::remove_all(dir);
  return frame;
}

// The recording holds the sensor's 8-bit RGB through the JPEG round trip, then in its own format:
// RGB24, YUYV and NV12 from the RGB's round trip, GREY from its grey plane's.
TEST(SimJpeg, SimulatedFramesHoldTheJpegRoundTrip) {
  const Frame rgb = simulate_one(board_scene(PixelFormat::RGB24, 0), "jpeg-rgb0");
  std::vector<uint8_t> expected = rgb.data;
  jpeg_round_trip(expected.data(), rgb.width, rgb.height, rgb.bytes_per_line, 3, 75);
  const Frame rgb75 = simulate_one(board_scene(PixelFormat::RGB24, 75), "jpeg-rgb75");
  EXPECT_EQ(rgb75.data, expected);
  EXPECT_NE(rgb75.data, rgb.data);
  for (const PixelFormat format : {PixelFormat::YUYV, PixelFormat::NV12}) {
    const Frame frame = simulate_one(board_scene(format, 75), "jpeg-yuv");
    EXPECT_EQ(frame.data, from_rgb24(expected.data(), rgb.width, rgb.height, format).data) << pixel_format_name(format);
  }
  const Frame grey = simulate_one(board_scene(PixelFormat::GREY, 0), "jpeg-grey0");
  std::vector<uint8_t> grey_expected = grey.data;
  jpeg_round_trip(grey_expected.data(), grey.width, grey.height, grey.bytes_per_line, 1, 75);
  EXPECT_EQ(simulate_one(board_scene(PixelFormat::GREY, 75), "jpeg-grey75").data, grey_expected);
}

TEST(SimJpeg, BayerIsRefused) {
  SimScene scene = board_scene(PixelFormat::SRGGB10, 75);
  SimulateOptions options;
  options.out_dir = scratch_dir("jpeg-bayer");
  options.frames = 1;
  try {
    simulate(scene, options);
    ADD_FAILURE() << "a Bayer camera with jpeg_quality simulated";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("camera.jpeg_quality"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("SRGGB10"), std::string::npos) << e.what();
  }
  fs::remove_all(options.out_dir);
}

// ---- Specular highlight ------------------------------------------------------------------------

// A plane at z = 0 lit by a point light at (0.1, 0, 0.5) and seen from (-0.2, 0, 0.3): the mirror
// point is x = (0.1 * 0.3 - 0.2 * 0.5) / 0.8 = -0.0875, where h = n and the lobe is at its height
// specular (m + 8) / (8 pi); elsewhere it is (n.h)^m of that, on top of albedo / pi.
TEST(SimSpecular, HighlightPeaksAtTheMirrorPointWithTheLobesHeight) {
  const Vec3 light_at{0.1, 0, 0.5}, eye{-0.2, 0, 0.3};
  const double intensity = 2.0, albedo = 0.3, specular = 0.2, shininess = 40;
  SimScene scene;
  SimObject plane = ground_plane("paper", 2, 2);
  plane.material.albedo = {albedo, albedo, albedo};
  plane.material.specular = specular;
  plane.material.shininess = shininess;
  scene.objects.push_back(plane);
  SimLight light;
  light.name = "lamp";
  light.kind = SimLight::Kind::Point;
  light.position = light_at;
  light.intensity = intensity;
  scene.lights.push_back(light);
  const SceneShader shader(scene, false);
  SimScene matte_scene = scene;
  matte_scene.objects[0].material.specular = 0;
  const SceneShader matte(matte_scene, false);

  const auto expected = [&](double x) {
    const Vec3 p{x, 0, 0};
    const Vec3 to_light = light_at - p, to_eye = eye - p;
    const double d2 = dot(to_light, to_light);
    const Vec3 w = normalized(to_light), v = normalized(to_eye);
    const double irradiance = intensity * w[2] / d2;
    const Vec3 h = normalized(w + v);
    return std::pair{albedo / kPi * irradiance,
                     specular * (shininess + 8) / (8 * kPi) * std::pow(h[2], shininess) * irradiance};
  };
  SampleRng rng(1, 1);
  double best_x = 0, best_ratio = -1;
  for (int k = -400; k <= 400; ++k) {
    const double x = -0.0875 + k * 0.0005;
    const Vec3 dir = normalized(Vec3{x, 0, 0} - eye);
    const Rgb glossy = shader.radiance(eye, dir, rng);
    const Rgb diffuse = matte.radiance(eye, dir, rng);
    const auto [diffuse_expected, highlight_expected] = expected(x);
    EXPECT_NEAR(diffuse[1], diffuse_expected, 1e-9 * diffuse_expected);
    EXPECT_NEAR(glossy[1], diffuse_expected + highlight_expected, 1e-9 * (diffuse_expected + highlight_expected));
    // The lobe alone, divided by the irradiance: (m + 8) / (8 pi) specular (n.h)^m, largest at h = n.
    const double ratio = (glossy[1] - diffuse[1]) / (diffuse_expected * kPi / albedo);
    if (ratio > best_ratio) best_ratio = ratio, best_x = x;
  }
  EXPECT_NEAR(best_x, -0.0875, 1e-9);
  EXPECT_NEAR(best_ratio, specular * (shininess + 8) / (8 * kPi), 1e-9);
}

// ---- Defaults and scene keys -------------------------------------------------------------------

TEST(SimPhotoEffects, DefaultsAreOffAndExplicitDefaultsChangeNothing) {
  const SimScene empty = parse_sim_scene("", "scene.toml", {});
  EXPECT_EQ(empty.camera.jpeg_quality, 0);
  EXPECT_EQ(empty.camera.optics.defocus_px, 0);
  EXPECT_EQ(empty.camera.optics.vignetting, 0);
  EXPECT_FALSE(empty.camera.optics.active());
  const std::string base =
      "[camera]\nwidth = 64\nheight = 48\n%s[render]\nsamples_per_pixel = 1\n[[object]]\nname = \"board\"\n"
      "%s[object.texture]\nkind = \"chessboard\"\n[[light]]\nkind = \"point\"\nposition = [0.05, 0, 0.2]\n"
      "intensity = 0.3\n[environment]\nradiance = [0.2, 0.2, 0.2]\n";
  const auto scene_text = [&](const std::string& camera, const std::string& object) {
    std::string text = base;
    text.replace(text.find("%s"), 2, camera);
    text.replace(text.find("%s"), 2, object);
    return text;
  };
  const SimScene plain = parse_sim_scene(scene_text("", ""), "scene.toml", {});
  const SimScene zeros = parse_sim_scene(
      scene_text("jpeg_quality = 0\n[camera.optics]\ndefocus_px = 0\nvignetting = 0\n", "specular = 0\n"), "scene.toml", {});
  EXPECT_EQ(zeros.objects[0].material.specular, 0);
  std::vector<uint8_t> bytes[2];
  for (int i = 0; i < 2; ++i) {
    const fs::path dir = scratch_dir(fmt::format("defaults{}", i));
    SimulateOptions options;
    options.out_dir = dir;
    options.frames = 2;
    simulate(i == 0 ? plain : zeros, options);
    bytes[i] = file_bytes(dir / "frames.bin");
    fs::remove_all(dir);
  }
  EXPECT_FALSE(bytes[0].empty());
  EXPECT_EQ(bytes[0], bytes[1]);
}

TEST(SimPhotoEffects, KeysLoad) {
  const SimScene scene = parse_sim_scene(
      "[camera]\njpeg_quality = 75\n[camera.optics]\ndefocus_px = 1.25\nvignetting = 0.5\n"
      "[[object]]\nspecular = 0.05\nshininess = 120\n",
      "scene.toml", {});
  EXPECT_EQ(scene.camera.jpeg_quality, 75);
  EXPECT_EQ(scene.camera.optics.defocus_px, 1.25);
  EXPECT_EQ(scene.camera.optics.vignetting, 0.5);
  EXPECT_EQ(scene.objects[0].material.specular, 0.05);
  EXPECT_EQ(scene.objects[0].material.shininess, 120);
}

void expect_error(const std::string& text, const std::string& place, const std::string& key, const std::string& detail) {
  const std::string message = error_of(text);
  EXPECT_EQ(message.rfind(place, 0), 0u) << message;
  EXPECT_NE(message.find(key), std::string::npos) << message;
  EXPECT_NE(message.find(detail), std::string::npos) << message;
}

TEST(SimPhotoEffects, OutOfRangeValuesNameFileLineAndKey) {
  expect_error("[camera]\njpeg_quality = 101\n", "scene.toml:2:", "camera.jpeg_quality", "100");
  expect_error("[camera]\njpeg_quality = -1\n", "scene.toml:2:", "camera.jpeg_quality", "-1");
  expect_error("[camera]\npixel_format = \"SRGGB10\"\njpeg_quality = 75\n", "scene.toml:3:", "camera.jpeg_quality",
               "SRGGB10");
  expect_error("[camera.optics]\ndefocus_px = 40\n", "scene.toml:2:", "camera.optics.defocus_px", "32");
  expect_error("[camera.optics]\ndefocus_px = -0.5\n", "scene.toml:2:", "camera.optics.defocus_px", "-0.5");
  expect_error("[camera.optics]\nvignetting = 1.5\n", "scene.toml:2:", "camera.optics.vignetting", "1.5");
  expect_error("[camera.optics]\nblur = 1\n", "scene.toml:2:", "camera.optics.blur", "unknown key");
  expect_error("[[object]]\nspecular = 2\n", "scene.toml:2:", "object[0].specular", "2");
  expect_error("[[object]]\nspecular = 0.1\nshininess = 0.5\n", "scene.toml:3:", "object[0].shininess", "0.5");
  expect_error("[[object]]\nshininess = 20\n", "scene.toml:2:", "object[0].shininess", "specular");
  expect_error("[[object]]\nshape = \"sphere\"\nmaterial = \"mirror\"\nspecular = 0.1\n", "scene.toml:4:",
               "object[0].specular", "mirror");
}

}  // namespace
}  // namespace arpipe::sim
