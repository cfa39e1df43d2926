// Draws the virtual objects into the bound framebuffer through the lens projection, each vertex
// placed with its own row's pose (row_poses.h): shaded colour for the virtual layer, or the
// per-pixel image velocity over the exposure that the velocity blur gathers along.
#pragma once

#include <span>

#include "render/gl_program.h"
#include "render/lens_projection.h"
#include "render/render_objects.h"
#include "render/row_poses.h"

namespace arpipe {

struct Lighting {
  Vec3 direction{0, 0, 1};  // world frame, unit, towards the light
  Vec3 color{1, 1, 1};
  Vec3 ambient{0, 0, 0};
};

struct ObjectAtInstant {
  const RenderObject* object = nullptr;
  RowPoses poses;  // T_cam_object per row, without the scale
};

struct ObjectOverExposure {
  const RenderObject* object = nullptr;
  RowPoses start, mid, end;  // at the start, middle and end of each row's exposure
};

class ObjectRenderer {
 public:
  // Compiles both programs; needs a current context. Throws RenderError.
  ObjectRenderer();

  // Linear, premultiplied colour with depth test, into the bound framebuffer (viewport and
  // scissor as set by the caller), with the lens as the projection.
  void draw(const LensUniforms& lens, const RowProjection& rows, const Lighting& lighting,
            std::span<const ObjectAtInstant> objects) const;
  // rg = end minus start image position (pixels of the lens image), b = depth at mid-exposure (m),
  // a = 1, with depth test at the mid-exposure position; for a float colour target.
  void draw_velocity(const LensUniforms& lens, const RowProjection& rows,
                     std::span<const ObjectOverExposure> objects) const;

 private:
  GlProgram shading_;
  GlProgram velocity_;
};

}  // namespace arpipe
