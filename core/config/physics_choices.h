// The physics choices of a config, with their name tables: how a virtual object moves
// (render.objects[].physics.kind), the shape it collides with (.shape), and the collider a proxy
// stands for (render.proxies[].collider). Mapped onto core/physics's specs by render/scene_physics.
#pragma once

#include "core/config/choice_names.h"

namespace arpipe {

enum class ObjectMotion {
  None,       // placed where the config says, no physics
  Static,     // a body that never moves; other bodies collide with it
  Dynamic,    // moved by gravity and contacts
  Kinematic,  // follows its pose track (render.objects[].physics.track) and pushes dynamic bodies
};
inline constexpr ChoiceName<ObjectMotion> kObjectMotionNames[] = {{"none", ObjectMotion::None},
                                                                  {"static", ObjectMotion::Static},
                                                                  {"dynamic", ObjectMotion::Dynamic},
                                                                  {"kinematic", ObjectMotion::Kinematic}};
inline std::string_view object_motion_name(ObjectMotion kind) { return choice_name(kObjectMotionNames, kind); }

// A body's collision shape. auto: a builtin sphere is a sphere, cube and box a box, cylinder a
// cylinder (with a circular section), anything else its convex hull.
enum class BodyShapeChoice { Auto, Sphere, Box, Cylinder, Hull };
inline constexpr ChoiceName<BodyShapeChoice> kBodyShapeNames[] = {{"auto", BodyShapeChoice::Auto},
                                                                  {"sphere", BodyShapeChoice::Sphere},
                                                                  {"box", BodyShapeChoice::Box},
                                                                  {"cylinder", BodyShapeChoice::Cylinder},
                                                                  {"hull", BodyShapeChoice::Hull}};

// A proxy's collider. auto: a builtin box or cube is a box, a cylinder a cylinder, a plane a thin
// box, a sphere a sphere, a file its triangles.
enum class ColliderChoice { Auto, Triangles, Hull, Box, Sphere, Cylinder };
inline constexpr ChoiceName<ColliderChoice> kColliderNames[] = {{"auto", ColliderChoice::Auto},
                                                                {"triangles", ColliderChoice::Triangles},
                                                                {"hull", ColliderChoice::Hull},
                                                                {"box", ColliderChoice::Box},
                                                                {"sphere", ColliderChoice::Sphere},
                                                                {"cylinder", ColliderChoice::Cylinder}};

}  // namespace arpipe
