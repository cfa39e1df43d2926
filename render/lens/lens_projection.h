// Projection through the calibrated lens inside the vertex shader: the GLSL function that maps a
// camera-frame point to GL clip space, and the camera model's intrinsics as its uniforms.
#pragma once

#include <array>
#include <string>
#include <string_view>

#include "core/geometry/camera_model.h"
#include "core/geometry/ods_projection.h"
#include "render/gl/gl_program.h"

namespace arpipe {

// Depth range of the virtual layer, metres along the optical axis.
inline constexpr double kNearPlaneM = 0.01;
inline constexpr double kFarPlaneM = 100.0;

struct LensUniforms {
  std::array<double, 4> focal_center{};  // fx, fy, cx, cy in pixels
  std::array<double, 8> distortion{};    // OpenCV order k1, k2, p1, p2, k3, k4, k5, k6; zeros beyond the model's
  bool distorted = false;                // false for LENSMODEL_PINHOLE
  int width = 0;
  int height = 0;
  // A stereo panorama's eye (core/geometry/ods_projection.h): points are drawn where that eye's
  // omnidirectional-stereo panorama holds them, the circle's axis being ods_up_cam (unit, camera
  // frame) through the camera's centre. Eye::Mono: as they are.
  Eye eye = Eye::Mono;
  OdsRig ods;
  Vec3 ods_up_cam{0, -1, 0};
};

// Whether the vertex shader can project through this mrcal lens model (render.lens = "vertex").
bool lens_model_supported(const std::string& lensmodel);
// Throws RenderError naming the model when the vertex shader cannot project through it.
void check_lens_model_supported(const CameraModel& model);
// Throws RenderError as above.
LensUniforms lens_uniforms(const CameraModel& model);

// GLSL ES 3.00 source (no #version line) declaring `vec4 camera_to_clip(vec3 p_cam)` (and the
// ods_projection_glsl() it calls first, whose uniforms set_lens_uniforms sets too): p_cam in the
// camera frame (x right, y down, z forward) goes to the clip position whose window coordinates
// are the model's pixel coordinates plus one half (GL pixel centres lie at +0.5, mrcal's at 0),
// with image row v on GL row v, so a read-back framebuffer is in image row order.
std::string_view lens_projection_glsl();
// Sets the uniforms that lens_projection_glsl() declares on a program that uses it; leaves it bound.
void set_lens_uniforms(const GlProgram& program, const LensUniforms& lens);

}  // namespace arpipe
