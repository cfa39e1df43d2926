// The simulator's geometry in Embree 3. Rectangles and spheres are user geometry whose callbacks
// solve the intersection in double precision from the query's own double origin and direction
// (passed in an extended RTCIntersectContext), so a mirror sphere's normal is exact.
#include "capture/sim/embree_scene.h"

#include <embree3/rtcore.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace arpipe::sim {

namespace {

enum class ShapeKind { Rectangle, Sphere, Triangles };

struct Shape {
  ShapeKind kind = ShapeKind::Rectangle;
  uint32_t id = 0;
  RectangleShape rectangle;
  SphereShape sphere;
  Vec3 rectangle_normal{0, 0, 1};
  std::vector<float> positions;  // one float of padding at the end: Embree reads vertices 16 bytes at a time
  std::vector<uint32_t> indices;
};

// What the callbacks need beyond Embree's single-precision ray. Embree hands the callbacks the
// context pointer it was given, so the extension sits right after the standard part.
struct QueryContext {
  RTCIntersectContext embree;
  Vec3 origin;
  Vec3 dir;
  uint32_t ignore;
  double t;  // the exact t of the last rectangle or sphere hit that was accepted
};
static_assert(std::is_standard_layout_v<QueryContext>);

double shape_t(const Shape& shape, const QueryContext& q, double tnear, double tfar) {
  return shape.kind == ShapeKind::Sphere ? intersect_sphere(q.origin, q.dir, shape.sphere, tnear, tfar)
                                         : intersect_rectangle(q.origin, q.dir, shape.rectangle, tnear, tfar);
}

// Only rtcIntersect1/rtcOccluded1 are used, so Embree calls these with N == 1.
void analytic_intersect(const RTCIntersectFunctionNArguments* args) {
  if (args->N != 1 || !args->valid[0]) return;
  const auto& shape = *static_cast<const Shape*>(args->geometryUserPtr);
  auto& q = *reinterpret_cast<QueryContext*>(args->context);
  RTCRayN* ray = RTCRayHitN_RayN(args->rayhit, 1);
  RTCHitN* hit = RTCRayHitN_HitN(args->rayhit, 1);
  float& tfar = RTCRayN_tfar(ray, 1, 0);
  const double t = shape_t(shape, q, RTCRayN_tnear(ray, 1, 0), tfar);
  if (!(t < kInfinity)) return;
  tfar = float(t);
  q.t = t;
  RTCHitN_Ng_x(hit, 1, 0) = 0;  // the caller computes the exact normal
  RTCHitN_Ng_y(hit, 1, 0) = 0;
  RTCHitN_Ng_z(hit, 1, 0) = 1;
  RTCHitN_u(hit, 1, 0) = 0;
  RTCHitN_v(hit, 1, 0) = 0;
  RTCHitN_primID(hit, 1, 0) = args->primID;
  RTCHitN_geomID(hit, 1, 0) = args->geomID;
  RTCHitN_instID(hit, 1, 0, 0) = args->context->instID[0];
}

void analytic_occluded(const RTCOccludedFunctionNArguments* args) {
  if (args->N != 1 || !args->valid[0]) return;
  const auto& shape = *static_cast<const Shape*>(args->geometryUserPtr);
  const auto& q = *reinterpret_cast<const QueryContext*>(args->context);
  if (shape.id == q.ignore) return;
  float& tfar = RTCRayN_tfar(args->ray, 1, 0);
  if (shape_t(shape, q, RTCRayN_tnear(args->ray, 1, 0), tfar) < kInfinity) tfar = -kInfinity;
}

// Float bounds that surely contain the double-precision shape, for a float ray to traverse.
void set_bounds(RTCBounds* b, Vec3 lower, Vec3 upper) {
  const double pad = 1e-6 * (1.0 + std::max({std::abs(lower[0]), std::abs(lower[1]), std::abs(lower[2]),
                                             std::abs(upper[0]), std::abs(upper[1]), std::abs(upper[2])}));
  b->lower_x = float(lower[0] - pad);
  b->lower_y = float(lower[1] - pad);
  b->lower_z = float(lower[2] - pad);
  b->upper_x = float(upper[0] + pad);
  b->upper_y = float(upper[1] + pad);
  b->upper_z = float(upper[2] + pad);
}

void analytic_bounds(const RTCBoundsFunctionArguments* args) {
  const auto& shape = *static_cast<const Shape*>(args->geometryUserPtr);
  if (shape.kind == ShapeKind::Sphere) {
    const SphereShape& s = shape.sphere;
    set_bounds(args->bounds_o, s.centre - Vec3{s.radius, s.radius, s.radius},
               s.centre + Vec3{s.radius, s.radius, s.radius});
    return;
  }
  const RectangleShape& r = shape.rectangle;
  Vec3 lower = r.centre, upper = r.centre;
  for (int i = 0; i < 3; ++i) {
    const double extent = std::abs(r.x_axis[size_t(i)]) * r.half_width + std::abs(r.y_axis[size_t(i)]) * r.half_height;
    lower[size_t(i)] -= extent;
    upper[size_t(i)] += extent;
  }
  set_bounds(args->bounds_o, lower, upper);
}

const char* error_name(RTCError error) {
  switch (error) {
    case RTC_ERROR_NONE:
      return "no error";
    case RTC_ERROR_UNKNOWN:
      return "unknown error";
    case RTC_ERROR_INVALID_ARGUMENT:
      return "invalid argument";
    case RTC_ERROR_INVALID_OPERATION:
      return "invalid operation";
    case RTC_ERROR_OUT_OF_MEMORY:
      return "out of memory";
    case RTC_ERROR_UNSUPPORTED_CPU:
      return "unsupported CPU";
    case RTC_ERROR_CANCELLED:
      return "cancelled";
  }
  return "unrecognised error";
}

}  // namespace

double intersect_sphere(const Vec3& o, const Vec3& d, const SphereShape& s, double tnear, double tfar) {
  const Vec3 oc = o - s.centre;
  const double b = dot(oc, d);
  // The discriminant from the ray's closest approach to the centre, not b^2 - c, which cancels
  // badly far from the sphere (Haines et al., Ray Tracing Gems ch. 7).
  const Vec3 perpendicular = oc - b * d;
  const double disc = s.radius * s.radius - dot(perpendicular, perpendicular);
  if (disc < 0) return kInfinity;
  const double q = -b - std::copysign(std::sqrt(disc), b);
  const double c = dot(oc, oc) - s.radius * s.radius;
  double t0 = q != 0 ? c / q : 0.0;
  double t1 = q;
  if (t0 > t1) std::swap(t0, t1);
  if (t0 > tnear && t0 < tfar) return t0;
  if (t1 > tnear && t1 < tfar) return t1;
  return kInfinity;
}

double intersect_rectangle(const Vec3& o, const Vec3& d, const RectangleShape& r, double tnear, double tfar) {
  const Vec3 n = cross(r.x_axis, r.y_axis);
  const double denominator = dot(d, n);
  if (denominator == 0) return kInfinity;
  const double t = dot(r.centre - o, n) / denominator;
  if (!(t > tnear && t < tfar)) return kInfinity;
  const Vec3 local = o + t * d - r.centre;
  if (std::abs(dot(local, r.x_axis)) > r.half_width || std::abs(dot(local, r.y_axis)) > r.half_height) return kInfinity;
  return t;
}

struct EmbreeScene::Impl {
  RTCDevice device = nullptr;
  RTCScene visible = nullptr;
  RTCScene shadow = nullptr;
  std::vector<std::unique_ptr<Shape>> shapes;
  std::string last_message;
  bool committed = false;

  void check(const char* what) {
    const RTCError error = rtcGetDeviceError(device);
    if (error != RTC_ERROR_NONE)
      throw std::runtime_error(
          fmt::format("Embree: {}: {}{}{}", what, error_name(error), last_message.empty() ? "" : ": ", last_message));
  }

  uint32_t add(std::unique_ptr<Shape> shape, ShapeRole role) {
    if (committed) throw std::logic_error("EmbreeScene: shapes must be added before commit()");
    const auto id = uint32_t(shapes.size());
    shape->id = id;
    // One geometry per scene that uses it (a geometry is attached to one scene here).
    for (const auto& [wanted, scene] : {std::pair{role.visible, visible}, std::pair{role.occludes, shadow}}) {
      if (!wanted) continue;
      RTCGeometry geometry = nullptr;
      if (shape->kind == ShapeKind::Triangles) {
        geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
        rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, shape->positions.data(), 0,
                                   3 * sizeof(float), (shape->positions.size() - 1) / 3);
        rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, shape->indices.data(), 0,
                                   3 * sizeof(uint32_t), shape->indices.size() / 3);
      } else {
        geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_USER);
        rtcSetGeometryUserPrimitiveCount(geometry, 1);
        rtcSetGeometryUserData(geometry, shape.get());
        rtcSetGeometryBoundsFunction(geometry, analytic_bounds, nullptr);
        rtcSetGeometryIntersectFunction(geometry, analytic_intersect);
        rtcSetGeometryOccludedFunction(geometry, analytic_occluded);
      }
      rtcCommitGeometry(geometry);
      rtcAttachGeometryByID(scene, geometry, id);
      rtcReleaseGeometry(geometry);
      check("adding a shape");
    }
    shapes.push_back(std::move(shape));
    return id;
  }

  void init_context(QueryContext& q, const Vec3& origin, const Vec3& dir, uint32_t ignore) const {
    rtcInitIntersectContext(&q.embree);
    q.origin = origin;
    q.dir = dir;
    q.ignore = ignore;
    q.t = kInfinity;
  }
};

namespace {

void set_ray(RTCRay& ray, const Vec3& origin, const Vec3& dir, double tnear, double tfar) {
  ray.org_x = float(origin[0]);
  ray.org_y = float(origin[1]);
  ray.org_z = float(origin[2]);
  ray.tnear = float(tnear);
  ray.dir_x = float(dir[0]);
  ray.dir_y = float(dir[1]);
  ray.dir_z = float(dir[2]);
  ray.time = 0;
  ray.tfar = float(tfar);
  ray.mask = 0xffffffffu;
  ray.id = 0;
  ray.flags = 0;
}

}  // namespace

EmbreeScene::EmbreeScene() : impl_(std::make_unique<Impl>()) {
  impl_->device = rtcNewDevice(nullptr);
  if (!impl_->device)
    throw std::runtime_error(fmt::format("Embree: cannot create a device: {}", error_name(rtcGetDeviceError(nullptr))));
  rtcSetDeviceErrorFunction(
      impl_->device,
      [](void* user, RTCError, const char* message) { static_cast<Impl*>(user)->last_message = message; }, impl_.get());
  impl_->visible = rtcNewScene(impl_->device);
  impl_->shadow = rtcNewScene(impl_->device);
  for (RTCScene scene : {impl_->visible, impl_->shadow}) rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
  impl_->check("creating the scenes");
}

EmbreeScene::~EmbreeScene() {
  if (impl_->visible) rtcReleaseScene(impl_->visible);
  if (impl_->shadow) rtcReleaseScene(impl_->shadow);
  if (impl_->device) rtcReleaseDevice(impl_->device);
}

uint32_t EmbreeScene::add_rectangle(const RectangleShape& rectangle, ShapeRole role) {
  if (!(rectangle.half_width > 0 && rectangle.half_height > 0))
    throw std::invalid_argument(fmt::format("EmbreeScene: a rectangle needs a positive size, got {} x {}",
                                            2 * rectangle.half_width, 2 * rectangle.half_height));
  auto shape = std::make_unique<Shape>();
  shape->kind = ShapeKind::Rectangle;
  shape->rectangle = rectangle;
  return impl_->add(std::move(shape), role);
}

uint32_t EmbreeScene::add_sphere(const SphereShape& sphere, ShapeRole role) {
  if (!(sphere.radius > 0))
    throw std::invalid_argument(fmt::format("EmbreeScene: a sphere needs a positive radius, got {}", sphere.radius));
  auto shape = std::make_unique<Shape>();
  shape->kind = ShapeKind::Sphere;
  shape->sphere = sphere;
  return impl_->add(std::move(shape), role);
}

uint32_t EmbreeScene::add_triangles(std::vector<float> positions, std::vector<uint32_t> indices, ShapeRole role) {
  const size_t vertices = positions.size() / 3;
  if (positions.size() % 3 != 0 || indices.size() % 3 != 0 || indices.empty())
    throw std::invalid_argument(
        fmt::format("EmbreeScene: a mesh needs xyz positions and whole triangles, got {} "
                    "coordinates and {} indices",
                    positions.size(), indices.size()));
  for (uint32_t index : indices)
    if (index >= vertices)
      throw std::invalid_argument(fmt::format("EmbreeScene: a mesh index {} is past its {} vertices", index, vertices));
  auto shape = std::make_unique<Shape>();
  shape->kind = ShapeKind::Triangles;
  shape->positions = std::move(positions);
  shape->positions.push_back(0.0f);
  shape->indices = std::move(indices);
  return impl_->add(std::move(shape), role);
}

void EmbreeScene::commit() {
  rtcCommitScene(impl_->visible);
  rtcCommitScene(impl_->shadow);
  impl_->check("building the scene");
  impl_->committed = true;
}

size_t EmbreeScene::shape_count() const { return impl_->shapes.size(); }

ShapeHit EmbreeScene::intersect(const Vec3& origin, const Vec3& dir, double tnear, double tfar) const {
  QueryContext q;
  impl_->init_context(q, origin, dir, ShapeHit::kNone);
  RTCRayHit rayhit;
  set_ray(rayhit.ray, origin, dir, tnear, tfar);
  rayhit.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rayhit.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(impl_->visible, &q.embree, &rayhit);

  ShapeHit hit;
  if (rayhit.hit.geomID == RTC_INVALID_GEOMETRY_ID) return hit;
  const Shape& shape = *impl_->shapes[rayhit.hit.geomID];
  hit.shape = shape.id;
  switch (shape.kind) {
    case ShapeKind::Rectangle:
      hit.t = q.t;
      hit.normal = cross(shape.rectangle.x_axis, shape.rectangle.y_axis);
      break;
    case ShapeKind::Sphere:
      hit.t = q.t;
      hit.normal = (1.0 / shape.sphere.radius) * (origin + hit.t * dir - shape.sphere.centre);
      break;
    case ShapeKind::Triangles: {
      hit.t = rayhit.ray.tfar;
      hit.triangle = rayhit.hit.primID;
      hit.b1 = rayhit.hit.u;
      hit.b2 = rayhit.hit.v;
      const uint32_t* tri = &shape.indices[size_t(hit.triangle) * 3];
      auto vertex = [&](uint32_t i) {
        const float* p = &shape.positions[size_t(i) * 3];
        return Vec3{p[0], p[1], p[2]};
      };
      const Vec3 v0 = vertex(tri[0]);
      hit.normal = normalized(cross(vertex(tri[1]) - v0, vertex(tri[2]) - v0));
      break;
    }
  }
  return hit;
}

bool EmbreeScene::occluded(const Vec3& origin, const Vec3& dir, double tnear, double tfar, uint32_t ignore) const {
  QueryContext q;
  impl_->init_context(q, origin, dir, ignore);
  RTCRay ray;
  set_ray(ray, origin, dir, tnear, tfar);
  rtcOccluded1(impl_->shadow, &q.embree, &ray);
  return ray.tfar == -std::numeric_limits<float>::infinity();
}

}  // namespace arpipe::sim
