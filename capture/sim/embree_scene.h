// The simulator's geometry in Embree 3: exact rectangles and spheres (user geometry, hit in double
// precision) and triangle meshes, with closest-hit and shadow-ray queries. Queries are thread-safe.
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include "core/geometry/vec.h"

namespace arpipe::sim {

inline constexpr double kInfinity = std::numeric_limits<double>::infinity();

// A flat rectangle: unit, orthogonal axes; its normal is x_axis x y_axis.
struct RectangleShape {
  Vec3 centre{0, 0, 0};
  Vec3 x_axis{1, 0, 0};
  Vec3 y_axis{0, 1, 0};
  double half_width = 0;
  double half_height = 0;
};

struct SphereShape {
  Vec3 centre{0, 0, 0};
  double radius = 0;
};

// The nearest t in (tnear, tfar) where the ray origin + t unit_dir meets the shape, else infinity.
// Double precision, stable near grazing and near the surface.
double intersect_sphere(const Vec3& origin, const Vec3& unit_dir, const SphereShape& sphere, double tnear, double tfar);
double intersect_rectangle(const Vec3& origin, const Vec3& unit_dir, const RectangleShape& rect, double tnear,
                           double tfar);

struct ShapeHit {
  static constexpr uint32_t kNone = 0xffffffffu;
  uint32_t shape = kNone;  // as returned by EmbreeScene::add_*
  uint32_t triangle = 0;   // meshes: the triangle's index
  double t = kInfinity;    // exact for rectangles and spheres, single precision for triangles
  double b1 = 0, b2 = 0;   // meshes: the point is (1 - b1 - b2) v0 + b1 v1 + b2 v2
  Vec3 normal{0, 0, 1};    // unit geometric normal: rectangle x × y, sphere outward, triangle v0 v1 v2 CCW
  bool hit() const { return shape != kNone; }
};

// Which queries a shape takes part in.
struct ShapeRole {
  bool visible = true;   // closest-hit queries (camera and mirror rays)
  bool occludes = true;  // shadow rays
};

class EmbreeScene {
 public:
  // Throws std::runtime_error with Embree's message when the device cannot be made.
  EmbreeScene();
  ~EmbreeScene();
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;

  // Shapes are numbered from 0 in the order they are added. Positions are world x, y, z per
  // vertex, indices three per triangle (counter-clockwise seen from the front).
  uint32_t add_rectangle(const RectangleShape& rectangle, ShapeRole role);
  uint32_t add_sphere(const SphereShape& sphere, ShapeRole role);
  uint32_t add_triangles(std::vector<float> positions, std::vector<uint32_t> indices, ShapeRole role);
  // Builds the acceleration structures; no shape may be added afterwards. Throws on Embree errors.
  void commit();

  // The nearest visible shape along origin + t unit_dir, t in (tnear, tfar).
  ShapeHit intersect(const Vec3& origin, const Vec3& unit_dir, double tnear = 0, double tfar = kInfinity) const;
  // Whether an occluding shape lies along the ray in (tnear, tfar). `ignore` names a rectangle or
  // sphere that does not count (a sphere light's own surface).
  bool occluded(const Vec3& origin, const Vec3& unit_dir, double tnear = 0, double tfar = kInfinity,
                uint32_t ignore = ShapeHit::kNone) const;

  size_t shape_count() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace arpipe::sim
