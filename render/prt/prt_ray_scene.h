// The PRT bake's ray queries against one triangle mesh, in Embree 3: shadow rays and closest hits
// (triangle, barycentrics, which face). Built once, then queried from any number of threads.
#pragma once

#include <cstdint>
#include <memory>
#include <span>

#include "core/geometry/vec.h"
#include "core/scene/mesh.h"

namespace arpipe {

struct PrtRayHit {
  bool hit = false;
  uint32_t triangle = 0;  // index into Mesh::indices / 3
  float b1 = 0, b2 = 0;   // the point is (1 - b1 - b2) v0 + b1 v1 + b2 v2
  float t = 0;
  bool front_face = false;  // the ray met the side that (v1 - v0) x (v2 - v0) points to (CCW seen from outside)
};

class PrtRayScene {
 public:
  // Copies the mesh's positions and indices (the mesh need not outlive the scene); the indices must
  // be in range (prt_bake validates them). Throws std::runtime_error with Embree's message.
  explicit PrtRayScene(const Mesh& mesh);
  ~PrtRayScene();
  PrtRayScene(const PrtRayScene&) = delete;
  PrtRayScene& operator=(const PrtRayScene&) = delete;

  // Whether any triangle lies along origin + t dir for t in (0, tfar). Thread-safe.
  bool occluded(const Vec3& origin, const Vec3& dir, float tfar = kNoLimit) const;
  // The nearest triangle along origin + t dir, t in (0, tfar). Thread-safe.
  PrtRayHit closest_hit(const Vec3& origin, const Vec3& dir, float tfar = kNoLimit) const;

  // The same for many rays from one origin (a vertex's hemisphere), through Embree's ray stream
  // flagged coherent; blocked[k] / hits[k] answer dirs[k]. Thread-safe.
  void occluded(const Vec3& origin, std::span<const Vec3> dirs, std::span<uint8_t> blocked) const;
  void closest_hits(const Vec3& origin, std::span<const Vec3> dirs, std::span<PrtRayHit> hits) const;

  static constexpr float kNoLimit = 3.0e38f;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace arpipe
