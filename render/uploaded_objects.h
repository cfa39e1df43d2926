// The scene's virtual objects as the render stage draws them: meshes loaded and uploaded once per
// configure, with their placement on the anchor and their base colours.
#pragma once

#include <array>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/config/config.h"
#include "core/geometry/se3.h"
#include "render/gl/gpu_mesh.h"
#include "core/scene/gltf_animation.h"
#include "core/scene/mesh.h"
#include "core/scene/occluder_levels.h"

namespace arpipe {

// Proxies under a stereo panorama are cut into triangles no longer than this (mesh_subdivide.h):
// each eye's offset bends a straight edge, which the rasteriser would draw straight between its
// projected ends (tests/render/panorama_stereo_test.cpp measures an edge 0.9 m away: 0.31 px
// mean error cut); and at most this many triangles each (the edge grows instead).
inline constexpr double kOdsMaxEdgeM = 0.1;
inline constexpr size_t kMaxStereoProxyTriangles = 1'000'000;

struct UploadedObject {
  std::string mesh_source;               // as the config names it, for messages
  std::shared_ptr<const GpuMesh> mesh;   // shared by objects that name the same mesh
  Bounds bounds;                         // in the object frame, scaled
  SE3 T_world_object;                    // placement without the scale
  double scale = 1.0;
  std::optional<std::array<float, 4>> base_color;  // set for builtin meshes (config colour); else the file's
  // The real ground under the objects (render/shadow/shadow_receiver.h), or a proxy that receives
  // shadows: drawn as the shadow's darkening, never as a surface.
  bool shadow_catcher = false;
  // A proxy of real geometry ([[render.proxies]]): draws depth and a transparent layer (the camera
  // shows), or the darkening of a shadow catcher; it is never shaded as a surface.
  bool proxy = false;
  bool writes_depth = true;   // false: a proxy that receives shadows but hides nothing
  bool casts_shadows = true;  // virtual objects; proxies with the cast_shadows role
  std::string name;           // a proxy's, for messages and results
  int viewpoint = -1;         // a proxy's panorama viewpoint (render.proxies.viewpoint); -1: every frame
  double specular = 0;  // weight of the environment's glossy reflection (config)
  // An object moved by the physics: its pose at an instant (CLOCK_MONOTONIC ns); T_world_object is
  // then the pose at the frame's mid-exposure. Empty: fixed at T_world_object.
  std::function<SE3(int64_t)> pose_at;
  bool present = true;  // false once the physics removed it (it left the world)
  // The radius of a sphere with the object's mean projected area (a convex body's is a quarter of
  // its surface), scaled: how much sky it hides from the ground beside it (object_renderer.h).
  double sky_radius_m = 0;
  // Its mesh bounds a convex solid (core/scene/mesh_convexity.h): it cannot shadow itself where it
  // faces the light (render/shadow/unshadowed_objects.h).
  bool closed_convex = false;
  // A large proxy's culling clusters (render/proxy_clusters.h): per part of its mesh, the part's
  // bounds in the object frame, scaled. Empty: drawn whole.
  std::vector<Bounds> cluster_bounds;
  // A proxy's coarser meshes for drawing it depth-only (core/scene/occluder_levels.h), finest
  // first, each with its error scaled (m); empty: always the full mesh.
  std::vector<std::shared_ptr<const GpuMesh>> occluder_levels;
  std::vector<double> occluder_level_errors_m;
};

// Whether a proxy stands in the frame's place: it belongs to every viewpoint, or to the one the
// frame shows (FrameMetadata::viewpoint; a frame without one shows every proxy).
inline bool proxy_at_viewpoint(const UploadedObject& proxy, const std::optional<int>& viewpoint) {
  return proxy.viewpoint < 0 || !viewpoint || proxy.viewpoint == *viewpoint;
}


// The meshes of render.objects read (and their PRT transfer baked or taken from the cache) on the
// CPU, without GL, so a reload can do it away from the processing thread. Each distinct mesh and
// prt mode is loaded once. Throws ConfigError for an unknown "builtin:" name and AssetError for a
// missing or bad file or a failed bake, naming the config key (render.objects[i].mesh) and the file.
struct LoadedMeshes {
  struct Entry {
    Mesh mesh;
    std::vector<float> transfer;  // 9 coefficients per vertex, or empty without PRT
    bool closed_convex = false;   // is_closed_convex(mesh)
  };
  std::vector<Entry> meshes;
  std::vector<size_t> mesh_of_object;  // per render.objects entry: its index in meshes
  // Per render.proxies entry: its mesh (sized builtins made at size_m) and its collision mesh
  // (collision_mesh; null: the mesh itself). Neither is scaled.
  struct Proxy {
    std::shared_ptr<const Mesh> mesh;
    std::shared_ptr<const Mesh> collision;
    std::vector<OccluderLevel> occluder_levels;  // made only for proxies that occlude
    // render.proxies[i].node: where the node stands in its file at the animation's start, and the
    // animation when it moves the node (render/proxy_animator.h); else at rest and null.
    ScaledPose node_rest;
    std::shared_ptr<const GltfAnimation> animation;
    int animation_node = -1;
  };
  std::vector<Proxy> proxies;
};
LoadedMeshes load_object_meshes(const Config& config);

// Uploads what load_object_meshes made of this same config and places the objects; needs a current
// GL context.
// cut_for_stereo: each mesh cut into triangles of at most kOdsMaxEdgeM (at its largest scale), the
// PRT transfer carried along (for a stereo panorama's eyes, as the proxies).
std::vector<UploadedObject> upload_objects(const Config& config, const LoadedMeshes& loaded, bool cut_for_stereo = false);
// The same for render.proxies (UploadedObject::proxy), in config order.
// cut_for_stereo: each cut into triangles of at most kOdsMaxEdgeM, without its coarser occluder
// levels (for a stereo panorama's eyes).
std::vector<UploadedObject> upload_proxies(const Config& config, const LoadedMeshes& loaded, bool cut_for_stereo = false);
// A proxy's placement: R = Rz(yaw) Ry(pitch) Rx(roll), at position_m.
SE3 proxy_placement(const SceneProxy& proxy);
// Where it stands at rest: that placement (and scale) after its node's place in its file at the
// animation's start (render.proxies[i].node; nothing without one).
ScaledPose proxy_rest_placement(const SceneProxy& proxy, const LoadedMeshes::Proxy& loaded);

// Both of the above, on the calling thread.
std::vector<UploadedObject> load_and_upload_objects(const Config& config);

}  // namespace arpipe
