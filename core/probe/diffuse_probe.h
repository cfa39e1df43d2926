// Beyond the seed: one light plus a first-order (SH bands 0-1) ambient fitted to a Lambertian probe's
// shading, radiance(n) = albedo/pi (E max(0, n.l) + a0 + a.n) per RGB channel (near light: .cpp).
#pragma once

#include "core/light/light_estimate.h"
#include "core/light/linear_patch.h"
#include "core/probe/probe_sphere.h"

namespace arpipe {

struct DiffuseFitOptions {
  int max_iterations = 30;
  int max_fit_pixels = 1500;  // the direction search uses at most this many pixels (strided)
  // A light near the probe (a lamp at 0.5 m from a 4 cm ball) moves the terminator towards itself
  // by r/D and brightens the near side; the fit models that with s = r / D. light_distance_m > 0
  // fixes D; else fit_distance fits it (true) or takes the light as infinitely far (false).
  double light_distance_m = 0;
  bool fit_distance = true;
};

struct DiffuseFitResult {
  bool ok = false;
  DirectionalLight light;        // direction, RGB irradiance (angular size unknown: 0)
  ShRgb9 ambient_sh{};           // radiance SH (bands 0 and 1) whose irradiance is a0 + a.n
  Vec3 ambient_constant{0, 0, 0};  // a0 per channel (irradiance)
  double rms_residual = 0;       // luminance, relative to the mean luminance of the fitted pixels
  double lit_fraction = 0;       // of fitted pixels with n.l > 0: both sides of the terminator
  double clipped_fraction = 0;   // of the region's pixels (left out of the fit)
  int pixels = 0;
  int iterations = 0;
  double light_distance_m = 0;   // the fitted (or given) distance; 0 = infinitely far
};

// Never throws; ok = false when too few unclipped pixels are left or the fit degenerates.
DiffuseFitResult fit_diffuse_probe(const ProbeSphere& sphere, const ProbeRegion& region, const LinearPatch& patch,
                                   const DiffuseFitOptions& options);

}  // namespace arpipe
