// The "real world" of the simulator: radiance arriving along a world ray, by ray casting the scene
// with Embree (direct light with shadow rays, one perfect-mirror bounce, the sky). Independent of
// render/ on purpose: the renderer is graded against this.
#pragma once

#include <memory>

#include "capture/sim/sample_rng.h"
#include "capture/sim/sim_scene.h"

namespace arpipe::sim {

class SceneShader {
 public:
  // Loads the textures, meshes and HDR sky and builds the Embree scene. include_virtual: whether
  // objects marked virtual take part (false for the camera frames, true for the ground-truth
  // composite). Throws AssetError naming the file when an asset cannot be read.
  SceneShader(const SimScene& scene, bool include_virtual);
  ~SceneShader();
  SceneShader(const SceneShader&) = delete;
  SceneShader& operator=(const SceneShader&) = delete;

  // Linear RGB radiance arriving at `origin` from direction -dir, i.e. seen along the unit ray
  // origin + t dir, t > 0. Draws its light-sampling random numbers (soft shadows, sphere lights,
  // the sky's ambient light) from rng only. Thread-safe (const): many threads call it at once.
  Rgb radiance(const Vec3& origin, const Vec3& dir, SampleRng& rng) const;
  // The same radiance (the same random numbers drawn), also saying whether the first surface
  // along the ray is a virtual object: what the ground-truth coverage counts.
  Rgb radiance(const Vec3& origin, const Vec3& dir, SampleRng& rng, bool& first_hit_virtual) const;
  // Whether the first surface along the ray is a virtual object (never, without include_virtual).
  bool sees_virtual_object(const Vec3& origin, const Vec3& dir) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace arpipe::sim
