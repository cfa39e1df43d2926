// Seeds 001/004's probe method, faithfully: the brightest-luminance 4-connected components of the
// probe's image (image domain) or of a (u, v) lattice on the sphere (sphere domain), largest first.
#pragma once

#include <vector>

#include "core/geometry/camera_model.h"
#include "core/geometry/se3.h"
#include "core/light/linear_patch.h"
#include "core/probe/probe_sphere.h"

namespace arpipe {

// Rec. 709 / sRGB luminance weights (the seed names none; these match the sRGB primaries that the
// camera response decodes to).
inline double rec709_luminance(double r, double g, double b) { return 0.2126 * r + 0.7152 * g + 0.0722 * b; }

struct BrightestComponentsOptions {
  int max_lights = 1;  // the seed's n (its experiments use 1)
  // Pixels with luminance >= l_max - tolerance belong to a maximum component. The seed says "equal
  // to l_max" (tolerance 0): with an 8-bit camera that is the clipped plateau of a highlight.
  double tolerance = 0;
  int lattice_u = 256;  // sphere domain: longitude samples (wrapping)
  int lattice_v = 128;  // sphere domain: latitude samples, cell centres from pole to pole
};

struct BrightestComponent {
  int size = 0;            // pixels (image domain) or lattice samples (sphere domain)
  Vec2 centroid_px{0, 0};  // image domain: mean pixel position
  Vec3 normal_world{0, 0, 1};  // n_s at the component's point n
  Vec3 light_world{0, 0, 1};   // unit, from the probe towards the light
  bool clipped = false;        // the component's pixels are clipped
};

struct BrightestComponentsResult {
  double l_max = 0;  // scene-linear luminance
  int samples = 0;   // pixels or lattice samples looked at
  std::vector<BrightestComponent> components;  // largest first, at most max_lights
};

// Light direction at a probe point: a mirror reflects the camera's ray, reflect(c_i, n_s) with
// c_i = normalize(n - c) (the seed prints -2 (c_i.n_s) n - c_i, a typo: its caption says "reflect
// c_i about n_s"). On a Lambertian sphere the brightest point's normal points at the light.
Vec3 highlight_light_direction(const ProbeSphere& sphere, const Vec3& camera_world, const Vec3& normal_world);

// Image domain: all pixels of the region. The centroid's true view ray (mrcal unproject, lens
// included) is intersected with the sphere analytically; no depth buffer is needed.
BrightestComponentsResult brightest_components_image(const ProbeSphere& sphere, const ProbeRegion& region, const LinearPatch& patch,
                            const CameraModel& model, const SE3& T_cam_world, const BrightestComponentsOptions& options);
// Sphere domain (the seed's choice): a uniform (u, v) lattice, vertices projected through the
// camera model and culled on the hidden hemisphere and at the rim, components in (u, v) with the
// longitude seam wrapped, the component's 3D unit normals averaged and renormalised.
BrightestComponentsResult brightest_components_sphere(const ProbeSphere& sphere, const ProbeRegion& region, const LinearPatch& patch,
                             const CameraModel& model, const SE3& T_cam_world, const BrightestComponentsOptions& options);

}  // namespace arpipe
