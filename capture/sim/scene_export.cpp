// A simulator scene's real objects and lights as one binary glTF.
#include "capture/sim/scene_export.h"

#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>

#include "capture/sim/sim_object_mesh.h"
#include "core/scene/builtin_meshes.h"

namespace arpipe::sim {
namespace {

// The object's triangles in its own frame, as the ray tracer sees them (sim_scene.h's shapes).
Mesh object_frame_mesh(const SimObject& object) {
  switch (object.shape) {
    case SimObject::Shape::Plane: return make_rectangle_mesh(object.width_m, object.height_m, 1);
    case SimObject::Shape::Sphere: {
      Mesh sphere = make_sphere_mesh(object.radius_m, 24);  // resting on z = 0: centred instead
      for (size_t v = 0; v < sphere.vertex_count(); ++v) sphere.positions[3 * v + 2] -= float(object.radius_m);
      return sphere;
    }
    case SimObject::Shape::Mesh: {
      Mesh mesh = sim_object_mesh(object);
      for (float& p : mesh.positions) p = float(p * object.mesh_scale);
      return mesh;
    }
  }
  throw std::invalid_argument(fmt::format("object \"{}\": an unknown shape", object.name));
}

MeshPart albedo_part(const SimObject& object, size_t first_index, size_t index_count) {
  MeshPart part;
  part.first_index = uint32_t(first_index);
  part.index_count = uint32_t(index_count);
  const Rgb& albedo = object.material.albedo;
  part.base_color = {float(albedo[0]), float(albedo[1]), float(albedo[2]), 1.0f};
  return part;
}

// A moving object as the hybrid viewer's animated proxy: its mesh in its own frame, one part of
// its albedo, placed over time by its keys.
GlbAnimatedNode animated_node(const SimObject& object) {
  GlbAnimatedNode node;
  node.name = object.name;
  node.mesh = object_frame_mesh(object);
  node.mesh.parts = {albedo_part(object, 0, node.mesh.indices.size())};
  for (const SimPoseKey& key : object.keyframes) node.keys.push_back({key.time_s, key.T_world_object});
  return node;
}

bool exported_as_animated(const SimObject& object) { return !object.is_virtual && !object.keyframes.empty(); }

}  // namespace

Mesh real_world_mesh(const SimScene& scene) { return real_world_mesh(scene, [](const Mesh& mesh) { return mesh; }); }

Mesh real_world_mesh(const SimScene& scene, const std::function<Mesh(const Mesh&)>& per_object) {
  Mesh world;
  world.source = scene.source_file.empty() ? "simulator scene" : scene.source_file.string();
  for (const SimObject& object : scene.objects) {
    if (object.is_virtual) continue;
    const Mesh mesh = per_object(object_frame_mesh(object));
    const uint32_t first_vertex = uint32_t(world.vertex_count());
    const Mat3& R = object.T_world_object.rotation();
    for (size_t v = 0; v < mesh.vertex_count(); ++v) {
      const Vec3 p = object.T_world_object * Vec3{mesh.positions[3 * v], mesh.positions[3 * v + 1], mesh.positions[3 * v + 2]};
      world.positions.insert(world.positions.end(), {float(p[0]), float(p[1]), float(p[2])});
      const Vec3 n = mesh.normals.size() == mesh.positions.size()
                         ? mat_mul(R, Vec3{mesh.normals[3 * v], mesh.normals[3 * v + 1], mesh.normals[3 * v + 2]})
                         : Vec3{0, 0, 1};
      world.normals.insert(world.normals.end(), {float(n[0]), float(n[1]), float(n[2])});
    }
    world.parts.push_back(albedo_part(object, world.indices.size(), mesh.indices.size()));
    for (uint32_t index : mesh.indices) world.indices.push_back(first_vertex + index);
  }
  if (world.indices.empty()) throw std::invalid_argument("the scene has no real object to export");
  return world;
}

std::vector<GltfLight> scene_lights(const SimScene& scene) {
  std::vector<GltfLight> out;
  for (const SimLight& light : scene.lights) {
    GltfLight g;
    g.name = light.name;
    g.color = {light.color[0], light.color[1], light.color[2]};
    if (light.kind == SimLight::Kind::Directional) {
      g.type = "directional";
      g.intensity = light.irradiance;
      g.direction = -1.0 * light.direction_to_light;
    } else {
      g.type = "point";
      g.intensity = light.intensity;
      g.position = light.position;
    }
    out.push_back(std::move(g));
  }
  return out;
}

std::vector<GlbAnimatedNode> animated_nodes(const SimScene& scene) {
  std::vector<GlbAnimatedNode> nodes;
  for (const SimObject& object : scene.objects)
    if (exported_as_animated(object)) nodes.push_back(animated_node(object));
  return nodes;
}

std::vector<uint8_t> export_scene_glb(const SimScene& scene) {
  constexpr std::string_view kGenerator = "arpipe simulate --export-glb";
  const std::vector<GlbAnimatedNode> animated = animated_nodes(scene);
  if (animated.empty()) return encode_glb(real_world_mesh(scene), kGenerator, scene_lights(scene));
  SimScene still = scene;  // the real objects that stand still, or none: an empty static mesh
  std::erase_if(still.objects, exported_as_animated);
  const bool any_still = std::any_of(still.objects.begin(), still.objects.end(),
                                     [](const SimObject& object) { return !object.is_virtual; });
  return encode_glb(any_still ? real_world_mesh(still) : Mesh{}, kGenerator, scene_lights(scene), animated,
                    kSceneAnimationName);
}

}  // namespace arpipe::sim
