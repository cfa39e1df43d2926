// CameraModel tests against independent references: analytic pinhole/stereographic formulas,
// OpenCV's projectPoints, and mrcal's own Python reading the files that save() writes.
#include <gtest/gtest.h>

#include <fmt/format.h>
#include <opencv2/calib3d.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "core/geometry/camera_model.h"

namespace arpipe {
namespace {

namespace fs = std::filesystem;

// A mild real-world-like lens for each model (OpenCV's distCoeffs order: k1 k2 p1 p2 k3 k4 k5 k6).
CameraModel opencv_model(int n) {
  std::vector<double> intrinsics{910.5, 905.25, 641.3, 478.9};
  const std::vector<double> distortion{-0.31, 0.12, 0.0011, -0.0017, -0.021, 0.013, 0.0031, 0.0023};
  const int count = n == 4 ? 4 : n == 5 ? 5 : 8;
  intrinsics.insert(intrinsics.end(), distortion.begin(), distortion.begin() + count);
  return CameraModel(fmt::format("LENSMODEL_OPENCV{}", n), intrinsics, 1280, 960);
}

std::vector<Vec3> points_in_view() {
  // A grid of points 0.5..8 m away spanning most of the ~70 degree field of view.
  std::vector<Vec3> points;
  for (double z : {0.5, 2.0, 8.0})
    for (double x = -0.6; x <= 0.6001; x += 0.15)
      for (double y = -0.45; y <= 0.4501; y += 0.15) points.push_back({x * z, y * z, z});
  return points;
}

fs::path temp_dir(const std::string& name) {
  const fs::path dir = fs::path(ARPIPE_BINARY_DIR) / "test_tmp" / "camera_model" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

void write_text(const fs::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

// Runs a command, returns its stdout; rc receives the exit status.
std::string run_command(const std::string& command, int& rc) {
  std::string output;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) {
    rc = -1;
    return output;
  }
  char buffer[4096];
  size_t n;
  while ((n = fread(buffer, 1, sizeof buffer, pipe)) > 0) output.append(buffer, n);
  const int status = pclose(pipe);
  rc = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return output;
}

// Expects a CameraModelError whose message contains every one of the fragments.
template <typename F>
void expect_error(F&& f, const std::vector<std::string>& fragments) {
  try {
    f();
    ADD_FAILURE() << "expected a CameraModelError";
  } catch (const CameraModelError& e) {
    const std::string message = e.what();
    for (const auto& fragment : fragments)
      EXPECT_NE(message.find(fragment), std::string::npos) << "'" << fragment << "' missing from: " << message;
  }
}

TEST(CameraModel, PinholeMatchesTheFormula) {
  const CameraModel m = CameraModel::pinhole(800, 820, 320.5, 240.25, 640, 480);
  EXPECT_TRUE(m.is_pinhole());
  EXPECT_TRUE(m.has_core());
  EXPECT_EQ(m.lensmodel(), "LENSMODEL_PINHOLE");
  for (const Vec3& p : points_in_view()) {
    const auto q = m.project(p);
    ASSERT_TRUE(q);
    // u = fx x/z + cx; a few roundings of values ~1e3: 1e-10 px.
    EXPECT_NEAR((*q)[0], 800 * p[0] / p[2] + 320.5, 1e-10);
    EXPECT_NEAR((*q)[1], 820 * p[1] / p[2] + 240.25, 1e-10);
  }
}

TEST(CameraModel, RoundTripsForPinholeAndOpenCvModels) {
  std::vector<CameraModel> models{CameraModel::pinhole(910.5, 905.25, 641.3, 478.9, 1280, 960), opencv_model(4),
                                  opencv_model(5), opencv_model(8)};
  for (const CameraModel& m : models) {
    SCOPED_TRACE(m.lensmodel());
    // mrcal unprojects distorted models by an iterative solve that stops near 1e-8 px; 1e-6 px
    // leaves margin and is still 1000x below any detector's noise. Pinhole is closed form.
    const double pixel_tolerance = m.is_pinhole() ? 1e-9 : 1e-6;
    for (double u = 0; u <= 1280; u += 80)
      for (double v = 0; v <= 960; v += 80) {
        const auto direction = m.unproject({u, v});
        ASSERT_TRUE(direction);
        EXPECT_NEAR(norm(*direction), 1.0, 1e-14);
        EXPECT_GT((*direction)[2], 0);
        const auto q = m.project(*direction);
        ASSERT_TRUE(q);
        EXPECT_NEAR((*q)[0], u, pixel_tolerance);
        EXPECT_NEAR((*q)[1], v, pixel_tolerance);
        // normalize() is the same ray divided by z.
        const auto xy = m.normalize({u, v});
        ASSERT_TRUE(xy);
        EXPECT_NEAR((*xy)[0], (*direction)[0] / (*direction)[2], 1e-12);
        EXPECT_NEAR((*xy)[1], (*direction)[1] / (*direction)[2], 1e-12);
      }
    for (const Vec3& p : points_in_view()) {
      const auto q = m.project(p);
      ASSERT_TRUE(q);
      const auto xy = m.normalize(*q);
      ASSERT_TRUE(xy);
      // 1e-6 px of unprojection error over a focal length of ~900 px: ~1e-9 in x/z.
      EXPECT_NEAR((*xy)[0], p[0] / p[2], 2e-9);
      EXPECT_NEAR((*xy)[1], p[1] / p[2], 2e-9);
    }
  }
}

TEST(CameraModel, OpenCvModelsAgreeWithCvProjectPoints) {
  for (const int n : {4, 5, 8}) {
    const CameraModel m = opencv_model(n);
    SCOPED_TRACE(m.lensmodel());
    const cv::Matx33d K(m.fx(), 0, m.cx(), 0, m.fy(), m.cy(), 0, 0, 1);
    const std::vector<double> D(m.intrinsics().begin() + 4, m.intrinsics().end());
    const std::vector<Vec3> points = points_in_view();
    std::vector<cv::Point3d> cv_points;
    for (const Vec3& p : points) cv_points.emplace_back(p[0], p[1], p[2]);
    std::vector<cv::Point2d> cv_pixels;
    cv::projectPoints(cv_points, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, D, cv_pixels);
    std::vector<Vec2> pixels;
    m.project(points, pixels);
    ASSERT_EQ(pixels.size(), cv_pixels.size());
    for (size_t i = 0; i < pixels.size(); ++i) {
      // Two implementations of the same closed-form polynomial: rounding only (reference: 1e-9 px).
      EXPECT_NEAR(pixels[i][0], cv_pixels[i].x, 1e-9);
      EXPECT_NEAR(pixels[i][1], cv_pixels[i].y, 1e-9);
    }
  }
}

TEST(CameraModel, StereographicMatchesTheFormulaAndProjectsBehind) {
  // mrcal's stereographic: q = f * 2 tan(theta/2) * (x, y)/|(x, y)| + c, theta = angle off +z.
  const CameraModel m("LENSMODEL_STEREOGRAPHIC", {500, 510, 640, 480}, 1280, 960);
  for (const Vec3& p : std::vector<Vec3>{{0.3, -0.2, 1.0}, {1, 1, 0.1}, {1, -2, -1}}) {
    const auto q = m.project(p);
    ASSERT_TRUE(q) << "stereographic projects even behind the camera";
    const double rho = std::hypot(p[0], p[1]);
    const double theta = std::atan2(rho, p[2]);
    EXPECT_NEAR((*q)[0], 500 * 2 * std::tan(theta / 2) * p[0] / rho + 640, 1e-9);
    EXPECT_NEAR((*q)[1], 510 * 2 * std::tan(theta / 2) * p[1] / rho + 480, 1e-9);
  }
}

TEST(CameraModel, OtherMrcalModelsRoundTrip) {
  std::vector<double> splined{700, 700, 640, 480};
  for (int i = 0; i < 2 * 8 * 6; ++i) splined.push_back(0.002 * std::sin(1.7 * i));
  const std::vector<CameraModel> models{
      CameraModel("LENSMODEL_OPENCV12",
                  {910, 905, 641, 479, -0.3, 0.12, 0.001, -0.002, -0.02, 0.01, 0.003, 0.002, 1e-4, 2e-4, -1e-4, 3e-5},
                  1280, 960),
      CameraModel("LENSMODEL_STEREOGRAPHIC", {500, 510, 640, 480}, 1280, 960),
      // f = 500 keeps the image inside one turn of longitude and half a turn of latitude.
      CameraModel("LENSMODEL_LONLAT", {500, 500, 640, 480}, 1280, 960),
      CameraModel("LENSMODEL_LATLON", {500, 500, 640, 480}, 1280, 960),
      CameraModel("LENSMODEL_CAHVOR", {900, 905, 640, 480, 0.01, -0.02, 0.001, 0.002, -0.003}, 1280, 960),
      CameraModel("LENSMODEL_SPLINED_STEREOGRAPHIC_order=3_Nx=8_Ny=6_fov_x_deg=120", splined, 1280, 960)};
  for (const CameraModel& m : models) {
    SCOPED_TRACE(m.lensmodel());
    for (double u = 0; u <= 1280; u += 160)
      for (double v = 0; v <= 960; v += 160) {
        const auto direction = m.unproject({u, v});
        ASSERT_TRUE(direction);
        const auto q = m.project(*direction);
        ASSERT_TRUE(q);
        // Same iterative-solve margin as above.
        EXPECT_NEAR((*q)[0], u, 1e-6);
        EXPECT_NEAR((*q)[1], v, 1e-6);
      }
  }
  // A splined model whose control points are all zero is the plain stereographic model (mrcal's
  // definition: the splines add to the stereographic projection).
  std::vector<double> zero_spline{500, 510, 640, 480};
  zero_spline.resize(4 + 2 * 8 * 6, 0.0);
  const CameraModel flat("LENSMODEL_SPLINED_STEREOGRAPHIC_order=3_Nx=8_Ny=6_fov_x_deg=120", zero_spline, 1280, 960);
  const CameraModel stereographic("LENSMODEL_STEREOGRAPHIC", {500, 510, 640, 480}, 1280, 960);
  for (const Vec3& p : points_in_view()) {
    EXPECT_NEAR((*flat.project(p))[0], (*stereographic.project(p))[0], 1e-9);
    EXPECT_NEAR((*flat.project(p))[1], (*stereographic.project(p))[1], 1e-9);
  }
  // CAHVORE projects but mrcal cannot unproject it: unproject says so instead of failing.
  const CameraModel cahvore("LENSMODEL_CAHVORE_linearity=0.00",
                            {900, 905, 640, 480, 0, 0, 0, 0, 0, 0, 0, 0}, 1280, 960);
  EXPECT_TRUE(cahvore.project({0.1, 0.1, 1}));
  EXPECT_FALSE(cahvore.unproject({640, 480}));
}

// normalize_near (Newton from a neighbour's solution, for the tag corner refiner) is normalize: the
// pixel it returns projects to within its 1e-9 px stop of the pixel asked, and it is mrcal's
// unprojection to mrcal's own 1e-8 px. A start that is no use falls back to mrcal.
TEST(CameraModel, NormalizeNearIsNormalizeFromANeighbour) {
  std::vector<double> splined{700, 700, 640, 480};
  for (int i = 0; i < 2 * 8 * 6; ++i) splined.push_back(0.002 * std::sin(1.7 * i));
  const std::vector<CameraModel> models{
      CameraModel::pinhole(910.5, 905.25, 641.3, 478.9, 1280, 960), opencv_model(4), opencv_model(8),
      CameraModel("LENSMODEL_OPENCV12",
                  {910, 905, 641, 479, -0.3, 0.12, 0.001, -0.002, -0.02, 0.01, 0.003, 0.002, 1e-4, 2e-4, -1e-4, 3e-5},
                  1280, 960),
      CameraModel("LENSMODEL_CAHVOR", {900, 905, 640, 480, 0.01, -0.02, 0.001, 0.002, -0.003}, 1280, 960),
      CameraModel("LENSMODEL_SPLINED_STEREOGRAPHIC_order=3_Nx=8_Ny=6_fov_x_deg=120", splined, 1280, 960)};
  for (const CameraModel& m : models) {
    SCOPED_TRACE(m.lensmodel());
    for (double u = 20; u <= 1260; u += 155)
      for (double v = 20; v <= 940; v += 115) {
        const auto exact = m.normalize({u, v});
        const auto neighbour = m.normalize({u + 4, v - 3});
        ASSERT_TRUE(exact && neighbour);
        const auto fast = m.normalize_near({u, v}, *neighbour);
        ASSERT_TRUE(fast);
        const auto q = m.project({(*fast)[0], (*fast)[1], 1.0});
        ASSERT_TRUE(q);
        EXPECT_NEAR((*q)[0], u, 1e-9);
        EXPECT_NEAR((*q)[1], v, 1e-9);
        // 1e-8 px over a focal length of ~700-900 px.
        EXPECT_NEAR((*fast)[0], (*exact)[0], 2e-10);
        EXPECT_NEAR((*fast)[1], (*exact)[1], 2e-10);
      }
    const auto fallback = m.normalize_near({300, 200}, Vec2{std::nan(""), 0});
    ASSERT_TRUE(fallback);
    EXPECT_EQ(*fallback, *m.normalize({300, 200}));
  }
  const CameraModel cahvore("LENSMODEL_CAHVORE_linearity=0.00",
                            {900, 905, 640, 480, 0, 0, 0, 0, 0, 0, 0, 0}, 1280, 960);
  EXPECT_FALSE(cahvore.normalize_near({640, 480}, {0, 0}));
}

TEST(CameraModel, PointsBehindAPinholeLikeCameraDoNotProject) {
  const CameraModel m = opencv_model(8);
  EXPECT_FALSE(m.project({0.1, 0.1, -1}));
  EXPECT_FALSE(m.project({0.1, 0.1, 0}));
  std::vector<Vec2> out;
  m.project({{0.1, 0.1, 1}, {0.1, 0.1, -1}, {0, 0, 2}}, out);
  ASSERT_EQ(out.size(), 3u);
  EXPECT_TRUE(std::isfinite(out[0][0]));
  EXPECT_TRUE(std::isnan(out[1][0]) && std::isnan(out[1][1]));
  EXPECT_NEAR(out[2][0], m.cx(), 1e-12);
  EXPECT_NEAR(out[2][1], m.cy(), 1e-12);
}

TEST(CameraModel, BatchCallsMatchSingleCalls) {
  const CameraModel m = opencv_model(8);
  const std::vector<Vec3> points = points_in_view();
  std::vector<Vec2> pixels;
  m.project(points, pixels);
  ASSERT_EQ(pixels.size(), points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    EXPECT_EQ(pixels[i][0], (*m.project(points[i]))[0]);
    EXPECT_EQ(pixels[i][1], (*m.project(points[i]))[1]);
  }
  pixels.push_back({1e7, 1e7});  // far outside the lens's domain: the solver gives up
  std::vector<Vec3> directions;
  m.unproject(pixels, directions);
  ASSERT_EQ(directions.size(), pixels.size());
  for (size_t i = 0; i + 1 < pixels.size(); ++i) {
    const Vec3 single = *m.unproject(pixels[i]);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(directions[i][k], single[k], 1e-12);
  }
  EXPECT_FALSE(m.unproject(pixels.back()));
  EXPECT_TRUE(std::isnan(directions.back()[0]));
}

TEST(CameraModel, SaveThenLoadIsBitExact) {
  const fs::path dir = temp_dir("save_load");
  // 1.23456789e-7 is the coefficient that mrcal's own C writer (%f) rounds to 0.
  const CameraModel original("LENSMODEL_OPENCV8",
                             {1234.5678901234567, 1234.9876543210987, 639.123456789, 479.987654321, -0.3141592653589793,
                              1.23456789e-7, 1e-300, -2.5e-12, 0.0, 1.0 / 3.0, -7.0 / 9.0, 123.456e-9},
                             1280, 960);
  const fs::path path = dir / "model.cameramodel";
  original.save(path);
  const CameraModel loaded = CameraModel::load(path);
  EXPECT_EQ(loaded.lensmodel(), original.lensmodel());
  EXPECT_EQ(loaded.intrinsics(), original.intrinsics());  // every double bit for bit
  EXPECT_EQ(loaded.width(), 1280);
  EXPECT_EQ(loaded.height(), 960);
  EXPECT_FALSE(fs::exists(path.string() + ".tmp"));
  // parse() of to_string() is the same thing without a file.
  EXPECT_EQ(CameraModel::parse(original.to_string(), "memory").intrinsics(), original.intrinsics());

  const std::string splined_name = "LENSMODEL_SPLINED_STEREOGRAPHIC_order=3_Nx=8_Ny=6_fov_x_deg=120";
  std::vector<double> splined{700, 700, 640, 480};
  for (int i = 0; i < 96; ++i) splined.push_back(0.001 * std::cos(i));
  CameraModel(splined_name, splined, 1280, 960).save(path);
  EXPECT_EQ(CameraModel::load(path).lensmodel(), splined_name);
  EXPECT_EQ(CameraModel::load(path).intrinsics(), splined);
}

TEST(CameraModel, MrcalPythonReadsSavedFileAndProjectsTheSame) {
  int rc = 0;
  run_command("/usr/bin/python3 -c 'import mrcal' 2>/dev/null", rc);
  if (rc != 0) GTEST_SKIP() << "/usr/bin/python3 cannot import mrcal";

  const fs::path dir = temp_dir("python");
  const CameraModel m("LENSMODEL_OPENCV8",
                      {1000.25, 1005.5, 645.125, 477.75, -0.25, 0.1, 1.23456789e-7, -0.0005, -0.02, 0.01, 0.003, 0.002},
                      1280, 960);
  const fs::path path = dir / "opencv8.cameramodel";
  m.save(path);
  const std::vector<Vec3> points{{0.1, -0.2, 1.0}, {-0.5, 0.3, 2.0}, {0.8, 0.6, 3.0}, {0, 0, 5}};
  std::string script = "import mrcal, numpy as np\n";
  script += fmt::format("m = mrcal.cameramodel('{}')\n", path.string());
  script += "lensmodel, intrinsics = m.intrinsics()\nprint(lensmodel)\n";
  script += "print(' '.join(repr(float(x)) for x in intrinsics))\nprint(m.imagersize()[0], m.imagersize()[1])\n";
  script += "p = np.array([";
  for (const Vec3& p : points) script += fmt::format("[{:.17g},{:.17g},{:.17g}],", p[0], p[1], p[2]);
  script += "])\nfor q in mrcal.project(p, lensmodel, intrinsics): print(repr(float(q[0])), repr(float(q[1])))\n";
  const fs::path script_path = dir / "check.py";
  write_text(script_path, script);
  const std::string output = run_command("/usr/bin/python3 " + script_path.string(), rc);
  ASSERT_EQ(rc, 0) << output;

  std::istringstream in(output);
  std::string lensmodel;
  std::getline(in, lensmodel);
  EXPECT_EQ(lensmodel, "LENSMODEL_OPENCV8");
  std::string line;
  std::getline(in, line);
  std::istringstream numbers(line);
  std::vector<double> intrinsics;
  for (std::string token; numbers >> token;) intrinsics.push_back(std::strtod(token.c_str(), nullptr));
  // Python parses the %.17g text itself: exactly the same doubles.
  EXPECT_EQ(intrinsics, m.intrinsics());
  int width = 0, height = 0;
  in >> width >> height;
  EXPECT_EQ(width, 1280);
  EXPECT_EQ(height, 960);
  for (const Vec3& p : points) {
    std::string qx, qy;
    in >> qx >> qy;
    const Vec2 ours = *m.project(p);
    // Same C projection code behind both, fed the same doubles: agreement to rounding.
    EXPECT_NEAR(ours[0], std::strtod(qx.c_str(), nullptr), 1e-9);
    EXPECT_NEAR(ours[1], std::strtod(qy.c_str(), nullptr), 1e-9);
  }
}

TEST(CameraModel, ReadsAFileWrittenLikeMrcalsPythonWriter) {
  // The layout of mrcal's cameramodel.py writer: comments, trailing commas, 'icam_intrinsics'
  // and a base85 'optimization_inputs' blob that the C reader skips.
  const std::string text =
      "# generated by mrcal-calibrate-cameras\n"
      "{\n"
      "    'lensmodel':  'LENSMODEL_OPENCV4',\n\n"
      "    # intrinsics are fx,fy,cx,cy,distortion0,distortion1,....\n"
      "    'intrinsics': [ 1000, 1001.5, 639.5, 479.5, -0.1, 0.01, 1e-05, -2e-05,],\n\n"
      "    'valid_intrinsics_region': [\n    [ 0, 0 ],\n    [ 1279, 0 ],\n    [ 1279, 959 ],\n],\n\n"
      "    # extrinsics are rt_fromref\n"
      "    'extrinsics': [ 0, 0, 0, 0, 0, 0,],\n\n"
      "    'imagersize': [ 1280, 960,],\n\n"
      "    'icam_intrinsics': 0,\n\n"
      "    'optimization_inputs': b'ABC{}[]#!$%&()*+-;<=>?@^_`{|}~xyz',\n\n"
      "}\n";
  const CameraModel m = CameraModel::parse(text, "python-written.cameramodel");
  EXPECT_EQ(m.lensmodel(), "LENSMODEL_OPENCV4");
  EXPECT_EQ(m.intrinsics(), (std::vector<double>{1000, 1001.5, 639.5, 479.5, -0.1, 0.01, 1e-05, -2e-05}));
  EXPECT_EQ(m.width(), 1280);
  EXPECT_EQ(m.height(), 960);
}

TEST(CameraModel, LoadErrorsNameTheFileAndThePlace) {
  const fs::path dir = temp_dir("errors");
  const fs::path missing = dir / "missing.cameramodel";
  expect_error([&] { CameraModel::load(missing); }, {missing.string(), "No such file"});
  expect_error([&] { CameraModel::load(dir); }, {dir.string(), "directory"});

  const fs::path corrupt = dir / "corrupt.cameramodel";
  write_text(corrupt, "\x89PNG\r\n garbage");
  expect_error([&] { CameraModel::load(corrupt); }, {corrupt.string() + ":1:1:", "expected '{'", "0x89"});

  const fs::path truncated = dir / "truncated.cameramodel";
  write_text(truncated, "{\n  'lensmodel': 'LENSMODEL_PINHOLE',\n  'intrinsics': [ 1000, 1000, 320,");
  expect_error([&] { CameraModel::load(truncated); }, {truncated.string() + ":3:", "the end of the file"});

  const fs::path unknown = dir / "unknown.cameramodel";
  write_text(unknown,
             "{\n  'lensmodel': 'LENSMODEL_FISHEYE9',\n  'intrinsics': [1000, 1000, 320, 240],\n"
             "  'extrinsics': [0, 0, 0, 0, 0, 0],\n  'imagersize': [640, 480],\n}\n");
  expect_error([&] { CameraModel::load(unknown); },
               {unknown.string() + ":2:16:", "unknown lens model 'LENSMODEL_FISHEYE9'", "LENSMODEL_OPENCV8"});

  const fs::path count = dir / "count.cameramodel";
  write_text(count,
             "{\n  'lensmodel': 'LENSMODEL_OPENCV4',\n  'intrinsics': [1000, 1000, 320, 240, 0.1, 0.01],\n"
             "  'extrinsics': [0, 0, 0, 0, 0, 0],\n  'imagersize': [640, 480],\n}\n");
  expect_error([&] { CameraModel::load(count); },
               {count.string() + ":3:17:", "'intrinsics' has 6 values, but LENSMODEL_OPENCV4 needs 8"});

  const fs::path no_size = dir / "no_size.cameramodel";
  write_text(no_size,
             "{ 'lensmodel': 'LENSMODEL_PINHOLE', 'intrinsics': [1000, 1000, 320, 240],\n"
             "  'extrinsics': [0, 0, 0, 0, 0, 0] }\n");
  expect_error([&] { CameraModel::load(no_size); }, {no_size.string(), "missing key 'imagersize'"});

  const fs::path bad_size = dir / "bad_size.cameramodel";
  write_text(bad_size,
             "{ 'lensmodel': 'LENSMODEL_PINHOLE', 'intrinsics': [1000, 1000, 320, 240],\n"
             "  'extrinsics': [0, 0, 0, 0, 0, 0], 'imagersize': [640, 0] }\n");
  expect_error([&] { CameraModel::load(bad_size); }, {bad_size.string() + ":2:51:", "2 positive integers"});

  const fs::path order = dir / "order.cameramodel";
  write_text(order,
             "{ 'intrinsics': [1000, 1000, 320, 240], 'lensmodel': 'LENSMODEL_PINHOLE',\n"
             "  'extrinsics': [0, 0, 0, 0, 0, 0], 'imagersize': [640, 480] }\n");
  expect_error([&] { CameraModel::load(order); }, {order.string() + ":1:17:", "'lensmodel' first"});

  const fs::path nan = dir / "nan.cameramodel";
  write_text(nan,
             "{ 'lensmodel': 'LENSMODEL_PINHOLE', 'intrinsics': [1000, nan, 320, 240],\n"
             "  'extrinsics': [0, 0, 0, 0, 0, 0], 'imagersize': [640, 480] }\n");
  expect_error([&] { CameraModel::load(nan); }, {nan.string() + ":1:51:", "item 1 is not a finite number"});

  const fs::path bad_focal = dir / "bad_focal.cameramodel";
  write_text(bad_focal,
             "{ 'lensmodel': 'LENSMODEL_PINHOLE', 'intrinsics': [0, 1000, 320, 240],\n"
             "  'extrinsics': [0, 0, 0, 0, 0, 0], 'imagersize': [640, 480] }\n");
  expect_error([&] { CameraModel::load(bad_focal); }, {bad_focal.string() + ":", "focal lengths"});

  expect_error([&] { CameraModel::parse("", "empty-source"); }, {"empty-source:1:1:", "expected '{'"});
}

TEST(CameraModel, ConstructorErrorsSayWhatWasExpected) {
  expect_error([] { CameraModel("LENSMODEL_NOPE", {1, 1, 0, 0}, 10, 10); }, {"unknown lens model 'LENSMODEL_NOPE'"});
  expect_error([] { CameraModel("LENSMODEL_SPLINED_STEREOGRAPHIC", {1, 1, 0, 0}, 10, 10); },
               {"missing or malformed configuration"});
  expect_error([] { CameraModel("LENSMODEL_OPENCV8", {1, 1, 0, 0}, 10, 10); }, {"needs 12 intrinsics, got 4"});
  expect_error([] { CameraModel("LENSMODEL_PINHOLE", {1, std::nan(""), 0, 0}, 10, 10); },
               {"intrinsics[1]", "not a finite number"});
  expect_error([] { CameraModel::pinhole(100, 100, 5, 5, 0, 10); }, {"imager size must be positive"});
}

TEST(CameraModel, SaveErrorNamesTheFile) {
  const fs::path target = fs::path(ARPIPE_BINARY_DIR) / "test_tmp" / "no_such_dir" / "x" / "model.cameramodel";
  expect_error([&] { CameraModel::pinhole(100, 100, 50, 50, 100, 100).save(target); },
               {target.string(), "cannot write camera model"});
}

}  // namespace
}  // namespace arpipe
