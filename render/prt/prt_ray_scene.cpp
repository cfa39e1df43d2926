// Embree 3 scene of one mesh for the PRT bake: one triangle geometry, built for fast traversal
// (the bake casts millions of rays at a scene built once).
#include "render/prt/prt_ray_scene.h"

#include <embree3/rtcore.h>
#include <fmt/format.h>

#include <cstring>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

namespace arpipe {
namespace {

// Embree reports errors through a callback; the last message is kept for the exception.
struct EmbreeErrors {
  std::mutex mutex;
  std::string message;
};

void on_embree_error(void* user, RTCError, const char* text) {
  auto* errors = static_cast<EmbreeErrors*>(user);
  std::lock_guard lock(errors->mutex);
  errors->message = text ? text : "";
}

}  // namespace

struct PrtRayScene::Impl {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  std::vector<Vec3> face_normals;  // (v1 - v0) x (v2 - v0), not normalised: only its sign is used
  EmbreeErrors errors;

  ~Impl() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }

  void check(const char* what) {
    if (rtcGetDeviceError(device) == RTC_ERROR_NONE) return;
    std::lock_guard lock(errors.mutex);
    throw std::runtime_error(fmt::format("Embree: {}: {}", what, errors.message.empty() ? "error" : errors.message));
  }
};

namespace {

RTCRay make_ray(const Vec3& origin, const Vec3& dir, float tfar) {
  RTCRay ray{};
  ray.org_x = float(origin[0]);
  ray.org_y = float(origin[1]);
  ray.org_z = float(origin[2]);
  ray.dir_x = float(dir[0]);
  ray.dir_y = float(dir[1]);
  ray.dir_z = float(dir[2]);
  ray.tnear = 0.0f;
  ray.tfar = tfar;
  ray.mask = 0xffffffffu;
  ray.flags = 0;
  ray.time = 0.0f;
  return ray;
}

}  // namespace

PrtRayScene::PrtRayScene(const Mesh& mesh) : impl_(std::make_unique<Impl>()) {
  impl_->device = rtcNewDevice(nullptr);
  if (!impl_->device)
    throw std::runtime_error(fmt::format("Embree: cannot create a device (error {})", int(rtcGetDeviceError(nullptr))));
  rtcSetDeviceErrorFunction(impl_->device, on_embree_error, &impl_->errors);
  impl_->scene = rtcNewScene(impl_->device);
  rtcSetSceneBuildQuality(impl_->scene, RTC_BUILD_QUALITY_HIGH);
  impl_->check("creating the scene");

  const size_t triangles = mesh.triangle_count();
  impl_->face_normals.resize(triangles);
  auto position = [&](uint32_t v) {
    return Vec3{mesh.positions[3 * size_t(v)], mesh.positions[3 * size_t(v) + 1], mesh.positions[3 * size_t(v) + 2]};
  };
  for (size_t t = 0; t < triangles; ++t) {
    const Vec3 a = position(mesh.indices[3 * t]), b = position(mesh.indices[3 * t + 1]),
               c = position(mesh.indices[3 * t + 2]);
    impl_->face_normals[t] = cross(b - a, c - a);
  }
  if (triangles > 0) {
    RTCGeometry geometry = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_TRIANGLE);
    // Embree pads the buffers it allocates itself (it reads vertices 16 bytes at a time).
    auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                                 3 * sizeof(float), mesh.vertex_count()));
    auto* indices = static_cast<uint32_t*>(
        rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), triangles));
    if (vertices && indices) {
      std::memcpy(vertices, mesh.positions.data(), 3 * mesh.vertex_count() * sizeof(float));
      std::memcpy(indices, mesh.indices.data(), 3 * triangles * sizeof(uint32_t));
    }
    rtcCommitGeometry(geometry);
    rtcAttachGeometry(impl_->scene, geometry);
    rtcReleaseGeometry(geometry);
    impl_->check("adding the mesh");
  }
  rtcCommitScene(impl_->scene);
  impl_->check("building the scene");
}

PrtRayScene::~PrtRayScene() = default;

bool PrtRayScene::occluded(const Vec3& origin, const Vec3& dir, float tfar) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay ray = make_ray(origin, dir, tfar);
  rtcOccluded1(impl_->scene, &context, &ray);
  return ray.tfar < 0.0f;  // Embree sets tfar to -inf when something blocks the ray
}

PrtRayHit PrtRayScene::closest_hit(const Vec3& origin, const Vec3& dir, float tfar) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit query{};
  query.ray = make_ray(origin, dir, tfar);
  query.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  query.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(impl_->scene, &context, &query);
  PrtRayHit hit;
  if (query.hit.geomID == RTC_INVALID_GEOMETRY_ID) return hit;
  hit.hit = true;
  hit.triangle = query.hit.primID;
  hit.b1 = query.hit.u;
  hit.b2 = query.hit.v;
  hit.t = query.ray.tfar;
  hit.front_face = dot(dir, impl_->face_normals[hit.triangle]) < 0;
  return hit;
}

void PrtRayScene::occluded(const Vec3& origin, std::span<const Vec3> dirs, std::span<uint8_t> blocked) const {
  thread_local std::vector<RTCRay> rays;
  rays.resize(dirs.size());
  for (size_t k = 0; k < dirs.size(); ++k) rays[k] = make_ray(origin, dirs[k], kNoLimit);
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;  // one origin, directions in sampler order
  if (!rays.empty()) rtcOccluded1M(impl_->scene, &context, rays.data(), unsigned(rays.size()), sizeof(RTCRay));
  for (size_t k = 0; k < dirs.size(); ++k) blocked[k] = rays[k].tfar < 0.0f;
}

void PrtRayScene::closest_hits(const Vec3& origin, std::span<const Vec3> dirs, std::span<PrtRayHit> hits) const {
  thread_local std::vector<RTCRayHit> queries;
  queries.resize(dirs.size());
  for (size_t k = 0; k < dirs.size(); ++k) {
    queries[k] = RTCRayHit{};
    queries[k].ray = make_ray(origin, dirs[k], kNoLimit);
    queries[k].hit.geomID = RTC_INVALID_GEOMETRY_ID;
    queries[k].hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  }
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  if (!queries.empty())
    rtcIntersect1M(impl_->scene, &context, queries.data(), unsigned(queries.size()), sizeof(RTCRayHit));
  for (size_t k = 0; k < dirs.size(); ++k) {
    const RTCRayHit& q = queries[k];
    PrtRayHit& hit = hits[k];
    hit = PrtRayHit{};
    if (q.hit.geomID == RTC_INVALID_GEOMETRY_ID) continue;
    hit.hit = true;
    hit.triangle = q.hit.primID;
    hit.b1 = q.hit.u;
    hit.b2 = q.hit.v;
    hit.t = q.ray.tfar;
    hit.front_face = dot(dirs[k], impl_->face_normals[hit.triangle]) < 0;
  }
}

}  // namespace arpipe
