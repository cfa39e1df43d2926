// The scene's virtual objects as the render stage draws them: meshes loaded and uploaded once per
// configure, with their placement on the anchor and their base colours.
#include "render/uploaded_objects.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <optional>
#include <stdexcept>

#include "core/log.h"
#include "core/scene/asset_error.h"
#include "core/scene/builtin_meshes.h"
#include "core/scene/gltf_loader.h"
#include "core/scene/mesh_convexity.h"
#include "core/scene/mesh_subdivide.h"
#include "render/prt/prt_cache.h"
#include "render/proxy_animator.h"
#include "render/proxy_clusters.h"

namespace arpipe {
namespace {

std::string config_name(const Config& config) {
  return config.file.empty() ? std::string("config") : config.file.string();
}

// Errors name the config key as well as the file (the message from the loader names the file and
// the place in it).
// key: "render.objects[2].mesh". Sized builtins (builtin:box, ...) are made at size_m with their
// faces split subdivisions x subdivisions.
Mesh load_mesh(const Config& config, const std::string& key, const std::string& source,
               const Vec3& size_m = {0.06, 0.06, 0.06}, int subdivisions = 8) {
  if (is_builtin_mesh_source(source)) {
    if (auto mesh = make_builtin_mesh(source, size_m, subdivisions)) return std::move(*mesh);
    throw ConfigError(fmt::format("{}: {}: unknown builtin mesh \"{}\" (expected "
                                  "{} or a glTF 2.0 file)",
                                  config_name(config), key, source, kBuiltinMeshNames));
  }
  try {
    return load_gltf_mesh(source);  // relative to the working directory, like every path in a config
  } catch (const std::exception& e) {
    throw AssetError(fmt::format("{}: {} = \"{}\": {}", config_name(config), key, source, e.what()));
  }
}

// Builtin faces are split only where the lens is applied per vertex (render.lens = "vertex": long
// edges must bend with it). A rolling shutter's skew is linear in the row to first order, which a
// whole face follows between its corners; and a software rasteriser shades whole 4 x 4 blocks
// along every triangle edge, so an 8 x 8 split of a cube's faces costs about half its shading time.
int builtin_subdivisions(const Config& config) { return config.render.lens == LensMode::Vertex ? 8 : 1; }

// A proxy's mesh must have triangles: one without hides and catches nothing, which is never meant.
// A proxy is never shaded, so a builtin's faces are split only where the lens is applied per
// vertex (render.lens = "vertex": long edges must bend with it); otherwise a box is 12 triangles,
// which matters on a software rasteriser (about a microsecond per triangle drawn).
std::shared_ptr<const Mesh> load_proxy_mesh(const Config& config, const std::string& key, const std::string& source,
                                            const Vec3& size_m) {
  Mesh mesh = load_mesh(config, key, source, size_m, builtin_subdivisions(config));
  if (mesh.triangle_count() == 0)
    throw AssetError(fmt::format("{}: {} = \"{}\": the mesh has no triangles", config_name(config), key, source));
  return std::make_shared<const Mesh>(std::move(mesh));
}

Bounds scaled(const Bounds& box, double scale) {
  Bounds out;
  for (size_t axis = 0; axis < 3; ++axis) {
    const double a = box.min[axis] * scale, b = box.max[axis] * scale;
    out.min[axis] = std::min(a, b);
    out.max[axis] = std::max(a, b);
  }
  return out;
}

// The first 3 bands of the object's baked transfer (from the cache, else baked now and cached),
// or nothing for prt = "off".
std::vector<float> transfer_for(const Config& config, size_t object_index, const std::string& mesh_source,
                                const Mesh& mesh, ObjectPrt prt) {
  if (prt == ObjectPrt::Off || mesh.vertex_count() == 0) return {};
  PrtBakeSettings settings;
  settings.kind = prt == ObjectPrt::Unshadowed ? TransferKind::Unshadowed
                  : prt == ObjectPrt::Shadowed ? TransferKind::Shadowed
                                               : TransferKind::Interreflected;
  settings.bands = config.render.prt.bands;
  settings.samples_per_axis = config.render.prt.samples;
  const std::filesystem::path cache_dir =
      config.render.prt.cache_dir.empty() ? default_prt_cache_dir() : config.render.prt.cache_dir;
  const auto start = std::chrono::steady_clock::now();
  PrtLoad load;
  try {
    load = load_or_bake_prt(mesh, settings, cache_dir);
  } catch (const std::exception& e) {
    throw AssetError(fmt::format("{}: render.objects[{}] (mesh \"{}\", prt = \"{}\"): {}", config_name(config),
                                 object_index, mesh_source, object_prt_name(prt), e.what()));
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // Baking is expected once per mesh (info); a transfer that could not be cached is baked again at
  // every start (a warning).
  if (load.baked)
    log::info("prt: baked {} transfer of {} ({} vertices, {} directions) in {:.2f} s{} ({})", object_prt_name(prt), mesh_source,
              mesh.vertex_count(), settings.samples_per_axis * settings.samples_per_axis, seconds,
              load.file.empty() ? std::string() : fmt::format(" into {}", load.file.string()), load.note);
  if (load.note.find("not cached") != std::string::npos) log::warn("prt: {}: {}", mesh_source, load.note);
  const size_t count = size_t(load.transfer.bands * load.transfer.bands);
  std::vector<float> first9;
  first9.reserve(9 * mesh.vertex_count());
  for (size_t v = 0; v < load.transfer.vertex_count(); ++v)
    for (size_t i = 0; i < 9; ++i) first9.push_back(i < count ? load.transfer.at(v)[i] : 0.0f);
  return first9;
}

// sqrt(area / (4 pi)): the sphere whose cross-section is the mesh's mean projected area.
double mean_projected_radius(const Mesh& mesh) {
  double area = 0;
  for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    const auto at = [&](uint32_t i) {
      return Vec3{mesh.positions[3 * size_t(i)], mesh.positions[3 * size_t(i) + 1], mesh.positions[3 * size_t(i) + 2]};
    };
    const Vec3 a = at(mesh.indices[t]), b = at(mesh.indices[t + 1]), c = at(mesh.indices[t + 2]);
    area += 0.5 * norm(cross(b - a, c - a));
  }
  return std::sqrt(area / (4 * 3.14159265358979323846));
}

// A glTF proxy's part (render.proxies[i].node, or the file without its moving nodes), with the
// node's place in the file and its animation.
void load_proxy_node(const Config& config, size_t i, LoadedMeshes::Proxy& entry) {
  const SceneProxy& proxy = config.render.proxies[i];
  const std::string where = fmt::format("{}: render.proxies[{}] (mesh \"{}\"{})", config_name(config), i, proxy.mesh,
                                        proxy.node.empty() ? "" : fmt::format(", node \"{}\"", proxy.node));
  try {
    auto mesh = std::make_shared<const Mesh>(load_gltf_mesh(proxy.mesh, GltfMeshSelection{proxy.node, proxy.skip_animated_nodes}));
    if (!proxy.node.empty()) {
      auto animation = std::make_shared<const GltfAnimation>(GltfAnimation::load(proxy.mesh, proxy.animation));
      const std::optional<int> node = animation->find_node(proxy.node);
      if (!node) throw AssetError(fmt::format("{}: no node \"{}\"", proxy.mesh, proxy.node));
      entry.node_rest = animation->node_pose_at(*node, 0);
      if (animation->moves(*node)) {
        entry.animation_node = *node;
        entry.animation = std::move(animation);
      }
    }
    entry.mesh = std::move(mesh);
  } catch (const ConfigError&) {
    throw;
  } catch (const std::exception& e) {
    throw AssetError(fmt::format("{}: {}", where, e.what()));
  }
  // Colliders are static (core/physics): one that moves with the video would need a kinematic body.
  // The role matters only where something collides (a render.objects[].physics body).
  const bool bodies = std::any_of(config.render.objects.begin(), config.render.objects.end(),
                                  [](const SceneObject& o) { return o.physics.kind != ObjectMotion::None; });
  if (entry.animation && proxy.roles.collide && bodies)
    throw ConfigError(fmt::format("{}: the animation \"{}\" moves the node, and an animated proxy cannot have the "
                                  "\"collide\" role (colliders stand still)",
                                  where, entry.animation->name()));
}

}  // namespace

LoadedMeshes load_object_meshes(const Config& config) {
  LoadedMeshes loaded;
  std::map<std::string, size_t> index_of;  // mesh source and prt mode -> loaded.meshes
  for (size_t i = 0; i < config.render.objects.size(); ++i) {
    const SceneObject& object = config.render.objects[i];
    const std::string key = object.mesh + "\n" + std::string(object_prt_name(object.prt));
    auto found = index_of.find(key);
    if (found == index_of.end()) {
      LoadedMeshes::Entry entry;
      entry.mesh = load_mesh(config, fmt::format("render.objects[{}].mesh", i), object.mesh, {0.06, 0.06, 0.06},
                             builtin_subdivisions(config));
      entry.transfer = transfer_for(config, i, object.mesh, entry.mesh, object.prt);
      entry.closed_convex = is_closed_convex(entry.mesh);
      loaded.meshes.push_back(std::move(entry));
      found = index_of.emplace(key, loaded.meshes.size() - 1).first;
    }
    loaded.mesh_of_object.push_back(found->second);
  }
  for (size_t i = 0; i < config.render.proxies.size(); ++i) {
    const SceneProxy& proxy = config.render.proxies[i];
    // A sized builtin needs every size it uses (a plane's z is not used).
    const size_t sizes_used = proxy.mesh == "builtin:plane" ? 2 : 3;
    if (builtin_mesh_is_sized(proxy.mesh))
      for (size_t k = 0; k < sizes_used; ++k)
        if (!(proxy.size_m[k] > 0))
          throw ConfigError(fmt::format("{}: render.proxies[{}].size_m[{}]: expected a size above 0 m for {}, found {}",
                                        config_name(config), i, k, proxy.mesh, proxy.size_m[k]));
    LoadedMeshes::Proxy entry;
    const std::string key = fmt::format("render.proxies[{}].mesh", i);
    if (proxy.node.empty() && !proxy.skip_animated_nodes) entry.mesh = load_proxy_mesh(config, key, proxy.mesh, proxy.size_m);
    else load_proxy_node(config, i, entry);
    if (!proxy.collision_mesh.empty())
      entry.collision = load_proxy_mesh(config, fmt::format("render.proxies[{}].collision_mesh", i), proxy.collision_mesh,
                                        proxy.size_m);
    if (proxy.roles.occlude && config.render.occluder_lod_px > 0 && config.render.lens != LensMode::Vertex)
      entry.occluder_levels = make_occluder_levels(*entry.mesh);
    loaded.proxies.push_back(std::move(entry));
  }
  return loaded;
}

SE3 proxy_placement(const SceneProxy& proxy) {
  return SE3::from_rt({0, 0, proxy.yaw_rad}, proxy.position_m) * SE3::from_rt({0, proxy.pitch_rad, 0}, {0, 0, 0}) *
         SE3::from_rt({proxy.roll_rad, 0, 0}, {0, 0, 0});
}

ScaledPose proxy_rest_placement(const SceneProxy& proxy, const LoadedMeshes::Proxy& loaded) {
  return compose(proxy_placement(proxy), proxy.scale, loaded.node_rest);
}

std::vector<UploadedObject> upload_proxies(const Config& config, const LoadedMeshes& loaded, bool cut_for_stereo) {
  if (loaded.proxies.size() != config.render.proxies.size())
    throw std::logic_error(fmt::format("upload_proxies: {} proxies loaded for a config with {}", loaded.proxies.size(),
                                       config.render.proxies.size()));
  std::vector<UploadedObject> out;
  // A stereo panorama's eyes move each point by its own offset (ods_projection.h), which straight
  // edges between projected vertices do not follow: proxies, often a room's walls and floors, are
  // cut into triangles of at most kOdsMaxEdgeM, and their coarser occluder levels left out.
  for (size_t i = 0; i < config.render.proxies.size(); ++i) {
    const SceneProxy& proxy = config.render.proxies[i];
    UploadedObject object;
    object.mesh_source = proxy.mesh;
    object.name = proxy.name.empty() ? fmt::format("proxy {}", i) : proxy.name;
    const ScaledPose placed = proxy_rest_placement(proxy, loaded.proxies[i]);
    std::optional<Mesh> cut;
    if (cut_for_stereo) {
      double edge_m = 0;
      cut = subdivided(*loaded.proxies[i].mesh, kOdsMaxEdgeM / placed.scale, kMaxStereoProxyTriangles, &edge_m);
      if (edge_m * placed.scale > kOdsMaxEdgeM * 1.0001)
        log::warn("proxy {}: cut to edges of {:.3g} m for stereo (not {} m: at most {} triangles)", object.name,
                  edge_m * placed.scale, kOdsMaxEdgeM, kMaxStereoProxyTriangles);
    }
    ClusteredMesh clustered = cluster_for_culling(cut ? *cut : *loaded.proxies[i].mesh);
    object.mesh = std::make_shared<const GpuMesh>(clustered.mesh);
    for (const Bounds& b : clustered.bounds) object.cluster_bounds.push_back(scaled(b, placed.scale));
    object.scale = placed.scale;
    object.bounds = scaled(loaded.proxies[i].mesh->bounds(), placed.scale);
    object.T_world_object = placed.pose;
    object.proxy = true;
    object.shadow_catcher = proxy.roles.receive_shadows;
    object.writes_depth = proxy.roles.occlude;
    object.casts_shadows = proxy.roles.cast_shadows;
    object.viewpoint = proxy.viewpoint;
    object.base_color = std::array<float, 4>{0, 0, 0, 0};
    std::string sizes;
    for (const OccluderLevel& level : cut ? std::vector<OccluderLevel>{} : loaded.proxies[i].occluder_levels) {
      object.occluder_levels.push_back(std::make_shared<const GpuMesh>(*level.mesh));
      object.occluder_level_errors_m.push_back(level.error * object.scale);
      sizes += fmt::format(", {} ({:.2g} mm)", level.mesh->triangle_count(), 1e3 * object.occluder_level_errors_m.back());
    }
    if (!sizes.empty())
      log::info("proxy {}: occluder levels of {} triangles{}", object.name, loaded.proxies[i].mesh->triangle_count(), sizes);
    out.push_back(std::move(object));
  }
  return out;
}

std::vector<UploadedObject> upload_objects(const Config& config, const LoadedMeshes& loaded, bool cut_for_stereo) {
  if (loaded.mesh_of_object.size() != config.render.objects.size())
    throw std::logic_error(fmt::format("upload_objects: {} objects loaded for a config with {}",
                                       loaded.mesh_of_object.size(), config.render.objects.size()));
  // Cut for a stereo panorama's eyes as the proxies are (kOdsMaxEdgeM at the largest scale an
  // object gives the mesh), the PRT transfer carried to the new vertices: the same shading.
  std::vector<double> largest_scale(loaded.meshes.size(), 0);
  for (size_t i = 0; i < config.render.objects.size(); ++i)
    largest_scale[loaded.mesh_of_object[i]] = std::max(largest_scale[loaded.mesh_of_object[i]], config.render.objects[i].scale);
  std::vector<std::shared_ptr<const GpuMesh>> uploaded;
  for (size_t m = 0; m < loaded.meshes.size(); ++m) {
    const LoadedMeshes::Entry& entry = loaded.meshes[m];
    if (!cut_for_stereo || largest_scale[m] <= 0) {
      uploaded.push_back(std::make_shared<const GpuMesh>(entry.mesh, entry.transfer));
      continue;
    }
    std::vector<float> transfer = entry.transfer;
    const Mesh cut = transfer.empty() ? subdivided(entry.mesh, kOdsMaxEdgeM / largest_scale[m], kMaxStereoProxyTriangles)
                                      : subdivided(entry.mesh, transfer, 9, kOdsMaxEdgeM / largest_scale[m], kMaxStereoProxyTriangles);
    if (cut.triangle_count() != entry.mesh.triangle_count())
      log::info("{}: cut from {} to {} triangles for the stereo eyes", entry.mesh.source, entry.mesh.triangle_count(),
                cut.triangle_count());
    uploaded.push_back(std::make_shared<const GpuMesh>(cut, transfer));
  }
  std::vector<UploadedObject> objects;
  for (size_t i = 0; i < config.render.objects.size(); ++i) {
    const SceneObject& object = config.render.objects[i];
    const size_t m = loaded.mesh_of_object[i];
    UploadedObject out;
    out.mesh_source = object.mesh;
    out.mesh = uploaded[m];
    out.scale = object.scale;
    out.specular = object.specular;
    out.bounds = scaled(loaded.meshes[m].mesh.bounds(), object.scale);
    out.sky_radius_m = object.scale * mean_projected_radius(loaded.meshes[m].mesh);
    out.closed_convex = loaded.meshes[m].closed_convex;
    out.T_world_object = SE3::from_rt({0, 0, object.yaw_rad}, object.position_m);
    if (is_builtin_mesh_source(object.mesh))
      out.base_color = std::array<float, 4>{static_cast<float>(object.color[0]), static_cast<float>(object.color[1]),
                                            static_cast<float>(object.color[2]), 1.0f};
    objects.push_back(std::move(out));
  }
  return objects;
}

std::vector<UploadedObject> load_and_upload_objects(const Config& config) {
  return upload_objects(config, load_object_meshes(config));
}

}  // namespace arpipe
