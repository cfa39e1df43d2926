// The ground catcher's ratio baked into a texture over its square. The ratio the catcher draws
// (object_renderer.h) depends on the ground point, the light, the shadow maps and the virtual
// objects' sky occlusion, never on the camera: while those stay the same, one bake serves every
// frame, the camera moving or not, and each frame's catcher costs one filtered lookup per pixel
// instead of the shadow filter's taps (PCSS: 72 per pixel).
//
// When to bake: when the inputs changed since the last bake (the light by more than
// same_catcher_light allows), unless they also changed on the frame before (a light estimated anew each frame, a moving caster): then the catcher is drawn
// per pixel, which costs less than a bake a frame. (The render stage asks on every frame with a
// shadow, a reused layer's too, so "the frame before" is the last frame, drawn or not.) So a still light over a still scene bakes on
// its first frame and never again. The texture holds at least two texels per canvas pixel at the
// point of the square nearest the camera (baked again, larger, when the camera comes closer), at
// most kMaxCatcherBakeTexels across (nearer than that, the catcher is drawn per pixel).
// 2048 across is 8 MB and, on llvmpipe, a bake of about 0.3 s (the first frame of 16 cubes seen
// from 0.45 m: 342 against 129 ms at 1024); such a scene's square needs 955-1127 texels, so at
// 1024 it was drawn per pixel on most frames, 72 lookups a pixel: its catcher pass took 7.1 ms a
// frame, baked 2.3 (docs/BENCHMARKS.md, "Scaling").
//
// Each bake is read back once to find its reach: the sky occlusion fades to 0 before the square's
// edge and a shadow covers part of it, so the catcher draws nothing over much of its square (a
// third on the default capture, more than half on sun-outdoor), and the frame's footprint needs
// only the reach (render_stage.cpp).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "core/geometry/se3.h"
#include "render/gl/texture_target.h"
#include "render/object_renderer.h"

namespace arpipe {

inline constexpr int kMinCatcherBakeTexels = 64;
// Texels per canvas pixel at the square's nearest point: 2 keeps the filtered lookup's blur of
// the contact shadow at the objects' feet to half a pixel.
inline constexpr double kCatcherBakeTexelsPerPixel = 2.0;
inline constexpr int kMaxCatcherBakeTexels = 2048;

// Whether two lights give the ground catcher the same ratio within 1/1000 (a quarter of 1/255).
// The ratio (A + V D) / (A + D) depends on the light through the luminance of the direct light D,
// of the ambient light at the ground's normal A and, with sky occlusion, of the ambient radiance's
// SH; moving A and D by dA and dD moves it by at most (D |dA| + A |dD|) / (A + D)^2, which is at
// most e when each moves by at most e times the larger of the two. So each may move by
// kCatcherBakeLightChange of the larger (the SH by that share of its largest coefficient). A light
// infinitely far reaches D only through its cosine on the ground (the ground's normal is up), so
// its direction counts only there; a lamp's direction and place may move by the layer reuse's
// 1e-4 (render/layer_reuse.h). The shadow maps must be the same.
inline constexpr double kCatcherBakeLightChange = 1e-3;
bool same_catcher_light(const Lighting& a, const Lighting& b);

// Texels across the catcher's square for kCatcherBakeTexelsPerPixel per canvas pixel at its nearest
// point to any of the camera centres (T_cam_world poses): that times side * focal_px / distance;
// infinite when a camera is on it.
double catcher_texels_needed(const UploadedObject& catcher, std::span<const SE3> T_cam_world, double focal_px);

class CatcherBake {
 public:
  // float_target: the GL can draw into half floats (the ratio is kept to 1/2048); without, it never bakes.
  explicit CatcherBake(bool float_target) : float_target_(float_target) {}

  // This frame's bake of the ground catcher (the last entry drawn under lighting.shadow), baked
  // now if it must be; texture 0: draw it per pixel. shadow_redrawn: a shadow map was drawn anew
  // this frame (its content changed). Leaves framebuffer 0 bound and the scissor test off.
  Lighting::BakedCatcher for_frame(ObjectRenderer& renderer, const Lighting& lighting, const UploadedObject& catcher,
                                   double texels_needed, bool shadow_redrawn);
  uint64_t bakes() const { return bakes_; }  // how many times it baked

  // The part of a bake's square (world x, y min and max, as square) outside which every bilinear
  // lookup of its texels (size x size, row-major from the square's min corner, red channel) is
  // exactly 0: the nonzero texels' centres grown by one texel and a margin, within the square.
  // None nonzero: min > max.
  static std::array<float, 4> reach_of(std::span<const float> red, int size, const std::array<float, 4>& square);

 private:
  // What the bake depends on: the light, compared as the catcher sees it (same_catcher_light), and
  // the rest exactly: the shadow maps, the sky's occluders, the catcher's square.
  struct Key {
    bool valid = false;
    Lighting light;
    std::vector<float> exact;
    bool matches(const Key& other) const;
  };
  Key key_of(const Lighting& lighting, const UploadedObject& catcher) const;

  bool float_target_;
  TextureTarget target_;
  int size_ = 0;                       // texels across the baked texture; 0: none yet
  std::array<float, 4> reach_{};       // the bake's reach (reach_of)
  Key baked_key_;                      // what the texture was baked from
  Key last_key_;                       // the last frame's inputs
  bool changed_last_frame_ = false;
  uint64_t shadow_generation_ = 0;     // counts redrawn shadow maps: part of the key
  uint64_t bakes_ = 0;
};

}  // namespace arpipe
