// Tests of the vertex-shader projection: the GL clip positions it computes, captured with
// transform feedback and mapped to pixels by GL's viewport rule, against CameraModel::project
// (mrcal) for PINHOLE and OPENCV4/5/8; and unsupported lens models are refused by name.
#include "render/lens/lens_projection.h"

#include <GLES3/gl3.h>
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <cmath>
#include <cstring>
#include <random>

#include "render/gl/egl_context.h"
#include "render/gl/gl_objects.h"
#include "render/gl/render_errors.h"

namespace arpipe {
namespace {

constexpr int kWidth = 640, kHeight = 480;

// Clip positions of camera-frame points, as the shared GLSL function computes them on the GPU.
std::vector<std::array<float, 4>> clip_positions_on_gpu(const CameraModel& model, const std::vector<Vec3>& points) {
  const std::string vertex_source = fmt::format(
      "#version 300 es\nprecision highp float;\n{}\n"
      "in vec3 a_p_cam;\nout vec4 v_clip;\n"
      "void main() {{ v_clip = camera_to_clip(a_p_cam); gl_Position = v_clip; }}\n",
      lens_projection_glsl());
  const std::string fragment_source = "#version 300 es\nprecision highp float;\nout vec4 c;\nvoid main() { c = vec4(1.0); }\n";
  GlProgram program("transform feedback probe", vertex_source, fragment_source, {"v_clip"});
  set_lens_uniforms(program, lens_uniforms(model));

  std::vector<float> input;
  for (const Vec3& p : points) input.insert(input.end(), {float(p[0]), float(p[1]), float(p[2])});
  GlVertexArray vertex_array = GlVertexArray::create();
  glBindVertexArray(vertex_array.get());
  GlBuffer input_buffer = GlBuffer::create();
  glBindBuffer(GL_ARRAY_BUFFER, input_buffer.get());
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(input.size() * sizeof(float)), input.data(), GL_STATIC_DRAW);
  const GLint location = glGetAttribLocation(program.id(), "a_p_cam");
  glEnableVertexAttribArray(GLuint(location));
  glVertexAttribPointer(GLuint(location), 3, GL_FLOAT, GL_FALSE, 0, nullptr);

  // A surfaceless context has no default framebuffer, and drawing needs a complete one even with
  // the rasteriser off.
  GlTexture target = GlTexture::create();
  glBindTexture(GL_TEXTURE_2D, target.get());
  glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA8, 1, 1);
  GlFramebuffer framebuffer = GlFramebuffer::create();
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer.get());
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, target.get(), 0);

  GlBuffer output_buffer = GlBuffer::create();
  glBindBuffer(GL_TRANSFORM_FEEDBACK_BUFFER, output_buffer.get());
  glBufferData(GL_TRANSFORM_FEEDBACK_BUFFER, GLsizeiptr(points.size() * 4 * sizeof(float)), nullptr, GL_STATIC_READ);
  glBindBufferBase(GL_TRANSFORM_FEEDBACK_BUFFER, 0, output_buffer.get());
  glEnable(GL_RASTERIZER_DISCARD);
  glBeginTransformFeedback(GL_POINTS);
  glDrawArrays(GL_POINTS, 0, GLsizei(points.size()));
  glEndTransformFeedback();
  glDisable(GL_RASTERIZER_DISCARD);

  std::vector<std::array<float, 4>> clip(points.size());
  const void* mapped = glMapBufferRange(GL_TRANSFORM_FEEDBACK_BUFFER, 0, GLsizeiptr(points.size() * 4 * sizeof(float)),
                                        GL_MAP_READ_BIT);
  EXPECT_NE(mapped, nullptr);
  if (mapped) std::memcpy(clip.data(), mapped, clip.size() * sizeof(clip[0]));
  glUnmapBuffer(GL_TRANSFORM_FEEDBACK_BUFFER);
  glBindVertexArray(0);
  EXPECT_EQ(glGetError(), GLenum(GL_NO_ERROR));
  return clip;
}

// Points spread over the whole image (and a little beyond) at depths from 5 cm to 20 m, made by
// unprojecting random pixels, so the comparison covers the strongly distorted corners too.
std::vector<Vec3> points_across_the_image(const CameraModel& model) {
  std::mt19937 random(12345);
  std::uniform_real_distribution<double> u(-10, kWidth + 10), v(-10, kHeight + 10), depth(0.05, 20.0);
  std::vector<Vec3> points;
  while (points.size() < 2000) {
    const std::optional<Vec3> ray = model.unproject({u(random), v(random)});
    if (!ray || (*ray)[2] <= 0) continue;
    points.push_back((depth(random) / (*ray)[2]) * *ray);
  }
  return points;
}

void expect_gpu_matches_camera_model(const CameraModel& model) {
  EglContext context(EglPlatformRequest::Auto);
  const std::vector<Vec3> points = points_across_the_image(model);
  const std::vector<std::array<float, 4>> clip = clip_positions_on_gpu(model, points);
  double worst = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    const std::optional<Vec2> truth = model.project(points[i]);
    ASSERT_TRUE(truth.has_value());
    // GL's viewport rule (window = (ndc + 1) * size / 2) and the pixel-centre offset: GL's pixel
    // centres are at +0.5, mrcal's at integers. Rows are not flipped (lens_projection.h).
    const double u = (double(clip[i][0]) / clip[i][3] + 1.0) * kWidth / 2 - 0.5;
    const double v = (double(clip[i][1]) / clip[i][3] + 1.0) * kHeight / 2 - 0.5;
    const double error = std::hypot(u - (*truth)[0], v - (*truth)[1]);
    worst = std::max(worst, error);
    // 0.05 px: the shader works in 32-bit floats (about 1e-7 relative, so ~1e-4 px on a 640 px
    // image); a wrong coefficient, order or pixel-centre convention is off by far more.
    ASSERT_LT(error, 0.05) << model.lensmodel() << " point " << i << " (" << points[i][0] << ", " << points[i][1]
                           << ", " << points[i][2] << ") GPU (" << u << ", " << v << ") mrcal (" << (*truth)[0] << ", "
                           << (*truth)[1] << ")";
    // Depth: NDC z from the near/far planes, as a standard perspective projection defines it.
    const double z = points[i][2];
    const double expected_ndc_z = (kFarPlaneM + kNearPlaneM) / (kFarPlaneM - kNearPlaneM) -
                                  2 * kFarPlaneM * kNearPlaneM / ((kFarPlaneM - kNearPlaneM) * z);
    EXPECT_NEAR(double(clip[i][2]) / clip[i][3], expected_ndc_z, 1e-4);
  }
  std::cout << model.lensmodel() << ": worst GPU vs mrcal distance " << worst << " px over " << points.size()
            << " points\n";
}

TEST(LensProjection, PinholeMatchesCameraModel) {
  expect_gpu_matches_camera_model(CameraModel::pinhole(520.0, 515.0, 322.7, 236.1, kWidth, kHeight));
}

TEST(LensProjection, OpenCv4MatchesCameraModel) {
  expect_gpu_matches_camera_model(
      CameraModel("LENSMODEL_OPENCV4", {510.0, 512.0, 318.2, 243.9, -0.28, 0.09, 0.0012, -0.0007}, kWidth, kHeight));
}

TEST(LensProjection, OpenCv5MatchesCameraModel) {
  expect_gpu_matches_camera_model(CameraModel(
      "LENSMODEL_OPENCV5", {510.0, 512.0, 318.2, 243.9, -0.28, 0.09, 0.0012, -0.0007, -0.015}, kWidth, kHeight));
}

TEST(LensProjection, OpenCv8MatchesCameraModel) {
  // A rational model with every coefficient non-zero, so a swapped pair would show.
  expect_gpu_matches_camera_model(CameraModel(
      "LENSMODEL_OPENCV8", {505.0, 508.0, 321.4, 238.6, 0.35, -0.12, 0.0011, -0.0009, 0.02, 0.62, -0.05, 0.03}, kWidth,
      kHeight));
}

TEST(LensProjection, UnsupportedLensModelIsRefusedByName) {
  const CameraModel stereographic("LENSMODEL_STEREOGRAPHIC", {400.0, 400.0, 319.5, 239.5}, kWidth, kHeight);
  EXPECT_FALSE(lens_model_supported(stereographic.lensmodel()));
  try {
    lens_uniforms(stereographic);
    FAIL() << "expected RenderError";
  } catch (const RenderError& e) {
    EXPECT_NE(std::string(e.what()).find("LENSMODEL_STEREOGRAPHIC"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("not supported by render.lens = \"vertex\""), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace arpipe
