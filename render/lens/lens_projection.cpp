// Projection through the calibrated lens inside the vertex shader: the GLSL function that maps a
// camera-frame point to GL clip space, and the camera model's intrinsics as its uniforms.
#include "render/lens/lens_projection.h"

#include <fmt/format.h>

#include "core/geometry/ods_projection.h"
#include "render/gl/render_errors.h"

namespace arpipe {
namespace {

constexpr std::string_view kLensProjectionGlsl = R"glsl(
uniform vec4 u_lens_focal_center;  // fx, fy, cx, cy
uniform vec4 u_lens_k1_k2_p1_p2;
uniform vec4 u_lens_k3_k4_k5_k6;
uniform bool u_lens_distorted;
uniform vec2 u_image_size;

const float kNear = NEAR_PLANE;
const float kFar = FAR_PLANE;

// OpenCV's rational radial plus tangential model, as mrcal's LENSMODEL_OPENCVn evaluates it.
vec2 lens_distort(vec2 p) {
  float k1 = u_lens_k1_k2_p1_p2.x, k2 = u_lens_k1_k2_p1_p2.y, p1 = u_lens_k1_k2_p1_p2.z, p2 = u_lens_k1_k2_p1_p2.w;
  float k3 = u_lens_k3_k4_k5_k6.x, k4 = u_lens_k3_k4_k5_k6.y, k5 = u_lens_k3_k4_k5_k6.z, k6 = u_lens_k3_k4_k5_k6.w;
  float r2 = dot(p, p);
  float radial = (1.0 + r2 * (k1 + r2 * (k2 + r2 * k3))) / (1.0 + r2 * (k4 + r2 * (k5 + r2 * k6)));
  float xy2 = 2.0 * p.x * p.y;
  return p * radial + vec2(p1 * xy2 + p2 * (r2 + 2.0 * p.x * p.x), p1 * (r2 + 2.0 * p.y * p.y) + p2 * xy2);
}

// A window position on the rasteriser's 1/256-pixel grid (llvmpipe's subpixel precision) before
// GL's viewport transform moves it: that transform rounds a little differently for a viewport
// placed elsewhere (the objects' own image, render/work_area.h), which can move a vertex to the
// next grid point and flip a sample at an edge; from a grid point its rounding comes back to it.
vec2 on_subpixel_grid(vec2 pixel) { return floor(pixel * 256.0 + 0.5) / 256.0; }

vec4 camera_to_clip(vec3 p_view) {
  // A stereo panorama's eye (core/geometry/ods_projection.h): the point where that eye's panorama
  // holds it; p_view itself for a mono view.
  vec3 p = ods_eye_point(p_view);
  vec2 clip_xy;
  if (p.z > kNear) {
    vec2 pixel = u_lens_distorted ? lens_distort(p.xy / p.z) : p.xy / p.z;
    pixel = on_subpixel_grid(u_lens_focal_center.xy * pixel + u_lens_focal_center.zw);
    clip_xy = ((2.0 * pixel + 1.0) / u_image_size - 1.0) * p.z;
  } else {
    // Behind the near plane (GL clips it away): written without the division, linear in p, so
    // that GL's clipping of a triangle reaching behind the camera stays exact.
    vec2 pixel_times_z = u_lens_focal_center.xy * p.xy + u_lens_focal_center.zw * p.z;
    clip_xy = (2.0 * pixel_times_z + p.z) / u_image_size - p.z;
  }
  float clip_z = (kFar + kNear) / (kFar - kNear) * p.z - 2.0 * kFar * kNear / (kFar - kNear);
  return vec4(clip_xy, clip_z, p.z);
}
)glsl";

std::string make_source() {
  std::string source = std::string(ods_projection_glsl()) + std::string(kLensProjectionGlsl);
  auto replace = [&](std::string_view token, double value) {
    source.replace(source.find(token), token.size(), fmt::format("{:.6f}", value));
  };
  replace("NEAR_PLANE", kNearPlaneM);
  replace("FAR_PLANE", kFarPlaneM);
  return source;
}

}  // namespace

bool lens_model_supported(const std::string& lensmodel) {
  return lensmodel == "LENSMODEL_PINHOLE" || lensmodel == "LENSMODEL_OPENCV4" || lensmodel == "LENSMODEL_OPENCV5" ||
         lensmodel == "LENSMODEL_OPENCV8";
}

void check_lens_model_supported(const CameraModel& model) {
  if (!lens_model_supported(model.lensmodel()))
    throw RenderError(fmt::format(
        "lens model {} is not supported by render.lens = \"vertex\" (it projects through LENSMODEL_PINHOLE, "
        "LENSMODEL_OPENCV4, LENSMODEL_OPENCV5 and LENSMODEL_OPENCV8); render.lens = \"map\" draws through any "
        "lens mrcal can unproject",
        model.lensmodel()));
}

LensUniforms lens_uniforms(const CameraModel& model) {
  check_lens_model_supported(model);
  const std::vector<double>& intrinsics = model.intrinsics();
  LensUniforms lens;
  for (size_t i = 0; i < 4; ++i) lens.focal_center[i] = intrinsics.at(i);
  for (size_t i = 4; i < intrinsics.size() && i - 4 < lens.distortion.size(); ++i) lens.distortion[i - 4] = intrinsics[i];
  lens.distorted = intrinsics.size() > 4;
  lens.width = model.width();
  lens.height = model.height();
  return lens;
}

std::string_view lens_projection_glsl() {
  static const std::string source = make_source();
  return source;
}

void set_lens_uniforms(const GlProgram& program, const LensUniforms& lens) {
  glUseProgram(program.id());  // glProgramUniform* is GLES 3.1; the target is 3.0
  auto f = [](double value) { return static_cast<float>(value); };
  glUniform4f(program.uniform("u_lens_focal_center"), f(lens.focal_center[0]), f(lens.focal_center[1]),
                     f(lens.focal_center[2]), f(lens.focal_center[3]));
  glUniform4f(program.uniform("u_lens_k1_k2_p1_p2"), f(lens.distortion[0]), f(lens.distortion[1]),
                     f(lens.distortion[2]), f(lens.distortion[3]));
  glUniform4f(program.uniform("u_lens_k3_k4_k5_k6"), f(lens.distortion[4]), f(lens.distortion[5]),
                     f(lens.distortion[6]), f(lens.distortion[7]));
  glUniform1i(program.uniform("u_lens_distorted"), lens.distorted ? 1 : 0);
  glUniform2f(program.uniform("u_image_size"), f(lens.width), f(lens.height));
  const double half_ipd = lens.eye == Eye::Left ? 0.5 * lens.ods.ipd_m : lens.eye == Eye::Right ? -0.5 * lens.ods.ipd_m : 0.0;
  glUniform1f(program.uniform("u_ods_eye"), f(half_ipd));
  glUniform3f(program.uniform("u_ods_up"), f(lens.ods_up_cam[0]), f(lens.ods_up_cam[1]), f(lens.ods_up_cam[2]));
  glUniform2f(program.uniform("u_ods_merge"), f(lens.ods.pole_merge_from_rad), f(lens.ods.pole_merge_to_rad));
}

}  // namespace arpipe
