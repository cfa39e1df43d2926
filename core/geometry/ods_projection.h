// Omnidirectional stereo (ODS): how a stereo 360° panorama is captured, and so how anything drawn
// over it must be projected for its disparity to match. Each pixel's ray leaves an eye on a
// horizontal circle about the panorama's vertical axis, tangent to the circle: the ray of direction
// d starts at the eye offset o(d), perpendicular to d's horizontal part, left of it for the left
// eye, of length r = ipd / 2 x taper(elevation of d). The taper (the rigs' "pole merge") brings
// the eyes together towards the poles, where an offset perpendicular to a vertical ray is not
// defined: 1 up to pole_merge_from, a raised-cosine fall to 0 at pole_merge_to (the angles Blender
// Cycles' spherical stereo calls Pole Merge From and To).
//
// A point p (relative to the circle's centre) seen by an eye lies on exactly one such ray (when it
// is outside the eye's circle): ods_eye_point() gives p - o, whose direction is that ray's and
// whose length is the distance along it, so a renderer that draws p - o through the view camera
// centred at the circle's centre draws p where the panorama's eye saw it.
#pragma once

#include <cstdint>
#include <string_view>

#include "core/geometry/vec.h"

namespace arpipe {

// Which eye a frame shows (FrameMetadata::eye); Pair: both, packed into one picture
// (core/pipeline/stereo_packer.h).
enum class Eye : uint8_t { Mono, Left, Right, Pair };
std::string_view eye_name(Eye eye);  // "mono", "left", "right", "pair"

struct OdsRig {
  double ipd_m = 0.064;              // the distance between the eyes
  double pole_merge_from_rad = 1.0471975511965976;  // 60 degrees: full separation up to here
  double pole_merge_to_rad = 1.3089969389957472;    // 75 degrees: none from here to the pole

  bool operator==(const OdsRig&) const = default;
};

// The eye's distance from the circle's centre for a ray of this elevation (radians, either sign).
double ods_eye_radius(const OdsRig& rig, double elevation_rad);

// The eye's position o (relative to the circle's centre) for the ray of unit direction d; up is
// the circle's axis (unit). Zero for Eye::Mono, and for a ray along the axis.
Vec3 ods_eye_origin(const OdsRig& rig, Eye eye, const Vec3& up, const Vec3& d);

// p - o(d), where d is the direction of the eye's ray through p: the point as the eye's panorama
// holds it (direction and distance from the circle's centre, as a mono panorama's point would be).
// p itself for Eye::Mono. A point inside the eye's circle (horizontal distance below r), which no
// ray reaches, moves by at most r (kept finite; such a point is a few centimetres from the viewer). The taper's dependence on the ray's
// own elevation is solved by fixed-point iteration (kOdsIterations rounds: the GLSL version below
// takes the same steps, so the CPU and the GPU agree).
inline constexpr int kOdsIterations = 3;
Vec3 ods_eye_point(const OdsRig& rig, Eye eye, const Vec3& up, const Vec3& p);

// GLSL ES 3.00 source declaring the uniforms u_ods_up (vec3, unit, in the camera frame),
// u_ods_eye (float: + half the ipd for the left eye, - for the right, 0 for none) and u_ods_merge
// (vec2: pole merge from, to, radians), and `vec3 ods_eye_point(vec3 p)`, the function above.
std::string_view ods_projection_glsl();

}  // namespace arpipe
