// A simulator scene's real world as the hybrid viewer's inputs (seed 003: the pre-rendered scene
// exports its geometry as proxies and its lights): every real object's triangles in the world
// frame in one mesh (a part per object, named by it, its albedo as the base colour), for
// render.proxies, and its lights as KHR_lights_punctual, for light.panorama.lights_file, in one
// binary glTF. `arpipe simulate --export-glb FILE` writes it. A real object with a pose track
// (SimObject::keyframes) is not in that mesh: it is an animated node of its own, named by it, moved
// by the file's animation "scene" (GltfAnimation::node_pose_at of the node equals object_pose_at).
#pragma once

#include <cstdint>
#include <functional>
#include <string_view>
#include <vector>

#include "capture/sim/sim_scene.h"
#include "core/scene/glb_writer.h"
#include "core/scene/gltf_loader.h"
#include "core/scene/mesh.h"

namespace arpipe::sim {

// The real objects (not the virtual ones) in the world frame, each at T_world_object (a moving one
// at its first key's pose: place the scene with scene_at_time first for another time): planes as
// their rectangles, spheres tessellated (24 rings), meshes at their size and scale. Throws
// AssetError or std::invalid_argument naming an object that cannot be made.
Mesh real_world_mesh(const SimScene& scene);
// The same with each object's mesh, in its own frame, first passed through `per_object` (a
// simplification for coarser proxies); each object keeps its albedo as one part.
Mesh real_world_mesh(const SimScene& scene, const std::function<Mesh(const Mesh&)>& per_object);

// The lights: directional ones (the sun among them) with their irradiance (W/m^2) as the
// intensity; point and sphere lights as points with their radiant intensity (W/sr), a sphere's
// size dropped. glTF's units are lux and candela: light.panorama.lights_scale converts.
std::vector<GltfLight> scene_lights(const SimScene& scene);

// The name of the animation that export_scene_glb writes.
inline constexpr std::string_view kSceneAnimationName = "scene";

// The real objects with a pose track, each as an animated node: its name, its mesh in its own
// frame (as real_world_mesh makes it before placing it; one part of its albedo), its keys.
std::vector<GlbAnimatedNode> animated_nodes(const SimScene& scene);

// All of it as a .glb (core/scene/glb_writer.h): a scene without moving real objects as
// real_world_mesh and scene_lights (no animation); else the real objects without keys as that
// static mesh (empty when there are none), the others as animated_nodes, in the animation
// kSceneAnimationName. Throws as above, or std::invalid_argument for a scene with no real object.
std::vector<uint8_t> export_scene_glb(const SimScene& scene);

}  // namespace arpipe::sim
