// How far an image patch moved between two frames, without finding any feature: one Gauss-Newton
// step of an affine Lucas-Kanade fit (with a gain and an offset for exposure), which for motions
// well under a pixel is the motion itself. The tracker uses it to tell a still camera (the tags'
// patch moved less than a few hundredths of a pixel) from a moving one.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

namespace arpipe {

struct PatchMotion {
  // The largest displacement the affine fit gives at the patch's corners. Edges sharper than a
  // pixel read about 1.1x high, never low (tests/core/image/image_motion_test.cpp).
  double max_corner_px = 0;
  double outlier_fraction = 0;  // pixels the fit leaves far off (an occluder, a glint, a large motion)
  // The brightness change the fit explains: current = (1 + gain) reference + offset (in levels).
  // A gain near -1 means the texture is gone (a flat picture "fits" that way).
  double gain = 0;
  double offset = 0;
};

// reference, current: width x height grey patches (rows `stride` bytes apart), the same place in
// two frames. nullopt when the patch has too little texture to measure motion (or is under 8 px).
std::optional<PatchMotion> patch_motion(const uint8_t* reference, size_t reference_stride, const uint8_t* current,
                                        size_t current_stride, int width, int height);

// A reference patch smoothed once (the fit smooths both patches), for a reference that later frames
// are measured against one after another: a still camera's tags.
struct SmoothedPatch {
  std::vector<float> pixels;  // width x height, smoothed
  int width = 0;
  int height = 0;
};
SmoothedPatch smoothed_patch(const uint8_t* image, size_t stride, int width, int height);
// The same as patch_motion on the patch `reference` was made from, to the bit.
std::optional<PatchMotion> patch_motion(const SmoothedPatch& reference, const uint8_t* current, size_t current_stride);

}  // namespace arpipe
