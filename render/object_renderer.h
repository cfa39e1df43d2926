// Draws the virtual objects into the bound framebuffer through the lens projection, each vertex
// placed with its own row's pose (row_poses.h): shaded colour for the virtual layer, or the
// per-pixel image velocity over the exposure that the velocity blur gathers along.
#pragma once

#include <array>
#include <compare>
#include <map>
#include <optional>
#include <utility>
#include <span>
#include <vector>

#include "render/gl/gl_program.h"
#include "core/image/pixel_rect.h"
#include "render/lens/lens_projection.h"
#include "render/uploaded_objects.h"
#include "render/row_poses.h"
#include "render/shadow/shadow_map.h"

namespace arpipe {

// A surface of base colour (albedo) c shows c * (ambient(n) + color * max(n.l, 0) * visibility)
// * exposure_scale, with ambient(n) = ambient + sum_i ambient_sh[i] * Y_i(n) (real SH, Green's
// order): for an estimate in scene-linear units, color = E / pi and ambient_sh the ambient
// irradiance's SH over pi, and exposure_scale turns scene-linear into the frame's linear pixels.
// A mesh with baked transfer (PRT) replaces ambient(n) by sum_i L_i T_i(vertex), with L the
// radiance_sh turned into the object's frame: the same light, self-shadowed.
struct Lighting {
  Vec3 direction{0, 0, 1};  // world frame, unit, towards the light
  bool local = false;       // a lamp at `position`: the direction is then taken per point
  Vec3 position{0, 0, 0};
  Vec3 color{1, 1, 1};
  Vec3 ambient{0, 0, 0};
  // The constant ambient (the config's fixed light) is a sky above the real ground: a real surface
  // that catches shadows takes it over the part of its view above the horizon, (1 + n_z) / 2, and
  // ground_radiance over the rest. Both 0 for an estimate, whose SH holds sky and ground.
  Vec3 ground_radiance{0, 0, 0};  // albedo x (direct + sky) irradiance / pi of the lit ground
  std::array<Vec3, 9> ambient_sh{};
  std::array<Vec3, 9> radiance_sh{};  // the ambient light as radiance SH (world), for PRT
  double exposure_scale = 1;
  const ShadowLookup* shadow = nullptr;  // nullptr: nothing is shadowed
  // The real casters' own map (proxies with cast_shadows); nullptr: none. The catcher's ratio is
  // (ambient (1 - sky occlusion) + visibility * direct) / (ambient + real visibility * direct),
  // its ambient as ground_radiance says.
  const ShadowLookup* real_shadow = nullptr;
  // The virtual objects that hide part of the sky from the catchers: spheres of their mean
  // projected area (x, y, z world, radius), at most kMaxSkyOccluders (the rest are left out).
  static constexpr size_t kMaxSkyOccluders = 16;
  std::vector<std::array<float, 4>> sky_occluders;
  // The ground catcher's square (world x, y min and max), towards whose edge the sky occlusion
  // fades to 0 so that no seam shows where the catcher ends.
  std::array<float, 4> catcher_patch{};
  // The ground catcher's ratio baked over its square (render/shadow/catcher_bake.h): a texture
  // whose alpha is what the catcher draws, over world x, y min and max. Texture 0: per pixel.
  // reach: the part of the square (world x, y min and max) outside which every lookup of the
  // texture is exactly 0, so the catcher draws nothing there; min > max: nowhere.
  struct BakedCatcher {
    GLuint texture = 0;
    std::array<float, 4> square{};
    std::array<float, 4> reach{};
  } baked_catcher;
  // The objects no shadow reaches this frame (render/shadow/unshadowed_objects.h): drawn without
  // the shadow lookups, which would all return 1 on them.
  std::vector<const UploadedObject*> unshadowed;
  // Where the ground catcher can be other than transparent (canvas pixels, no two overlapping):
  // it is drawn only there, within the pass's scissor, which must then be its cull rectangle on
  // the whole canvas's viewport. None: everywhere (an empty list: nowhere).
  std::optional<std::vector<PixelRect>> ground_catcher_rects;
};

struct ObjectAtInstant {
  const UploadedObject* object = nullptr;
  RowPoses poses;  // T_cam_object per row, without the scale
};

struct ObjectOverExposure {
  const UploadedObject* object = nullptr;
  RowPoses start, mid, end;  // at the start, middle and end of each row's exposure
};

// Which shading program draws a surface: the branches a frame would take the same way for every
// pixel are compiled in or out, not chosen by uniforms.
struct ShadingVariant {
  ShadowMethod method = ShadowMethod::Off;  // the virtual objects' shadow lookup
  bool real_shadow = false;                 // with the real casters' map (proxies that cast), else a constant 1
  bool catcher = false;                     // a shadow catcher's ratio, not a surface's colour
  bool prt = false;                         // a surface's environment light from its transfer (seed 002)
  bool specular = false;                    // a surface's glossy reflection
  auto operator<=>(const ShadingVariant&) const = default;
};

class ObjectRenderer {
 public:
  // Compiles both programs; needs a current context. Throws RenderError.
  ObjectRenderer();
  // Compiles the shading program that reads this method's shadow map now, not on first use.
  void prepare(ShadowMethod method);

  // Linear, premultiplied colour with depth test, into the bound framebuffer (viewport and
  // scissor as set by the caller), with the lens as the projection. A shadow catcher
  // (UploadedObject::shadow_catcher) draws no colour: its alpha is 1 - the ratio by which the
  // virtual objects' shadow darkens the real ground, (ambient + visibility * direct) /
  // (ambient + real visibility * direct) in luminance, so the composite multiplies the camera
  // frame by that ratio. Any other proxy draws (0, 0, 0, 0): only its depth, so the camera shows.
  // A proxy that hides nothing (UploadedObject::writes_depth false) leaves the depth alone; the
  // caller draws those first.
  // cull_rect: the canvas pixels being drawn; a large proxy's clusters outside it are skipped.
  // occluder_lod_px: a proxy drawn depth-only uses its coarsest occluder level that strays at most
  // this far at its nearest point (UploadedObject::occluder_levels); 0: its full mesh.
  void draw(const LensUniforms& lens, const RowProjection& rows, const Lighting& lighting,
            std::span<const ObjectAtInstant> objects, const PixelRect& cull_rect, double occluder_lod_px = 0);
  // Draws the ground catcher as draw() would, but under what the bound framebuffer holds already
  // (premultiplied: dst + (1 - dst.a) src), without depth: into the resolved layer, after the
  // objects were drawn and resolved without it. Where an object covers a fraction a of a pixel's
  // samples this gives a object + (1 - a) catcher, as multisampling both together does (both are
  // shaded once per pixel), at one sample per pixel over the catcher's large patch.
  void draw_ground_catcher_under(const LensUniforms& lens, const RowProjection& rows, const Lighting& lighting,
                                 const ObjectAtInstant& catcher, const PixelRect& cull_rect);
  // The ground catcher's depth alone (no colour), a little behind its true depth (a polygon
  // offset, so that an object standing on the ground wins along its foot): drawn before the objects
  // whose catcher comes under them, so that what of an object lies below the ground stays hidden.
  void draw_ground_catcher_depth(const LensUniforms& lens, const RowProjection& rows, const ObjectAtInstant& catcher);
  // Draws the ground catcher's alpha (1 - ratio, as draw() gives it per pixel) over the world
  // square (x, y min and max) into the bound framebuffer's viewport, x right and y up: the texel
  // centre (i + 0.5, j + 0.5) / size holds the ground point there. Needs lighting.shadow.
  void bake_ground_catcher(const Lighting& lighting, const UploadedObject& catcher, const std::array<float, 4>& square);
  // rg = end minus start image position (pixels of the lens image), b = depth at mid-exposure (m),
  // a = 1, with depth test at the mid-exposure position; for a float colour target.
  void draw_velocity(const LensUniforms& lens, const RowProjection& rows,
                     std::span<const ObjectOverExposure> objects) const;

 private:
  // under: as draw_ground_catcher_under (no depth test, blended under the framebuffer's contents).
  void draw_items(const LensUniforms& lens, const RowProjection& rows, const Lighting& lighting,
                  std::span<const ObjectAtInstant> objects, const PixelRect& cull_rect, double occluder_lod_px,
                  bool under);
  const GlProgram& shading(const ShadingVariant& variant);
  // Binds the program and sets what every item drawn with it shares: lens, rows and light.
  void set_frame_uniforms(const GlProgram& program, const LensUniforms& lens, const RowProjection& rows,
                          const Lighting& lighting) const;
  std::map<ShadingVariant, GlProgram> shading_;
  // The same fragment shader placed on the ground catcher's bake texture.
  const GlProgram& baking(ShadowMethod method, bool real_shadow);
  std::map<ShadingVariant, GlProgram> baking_;
  // The fragment-side uniforms: the light, the shadow lookups, the catcher's; binds the program.
  void set_light_uniforms(const GlProgram& program, const Lighting& lighting) const;
  void set_object_placement(const GlProgram& program, const UploadedObject& object) const;
  GlProgram velocity_;
  GlProgram occluder_;  // proxies that hide but catch no shadow: depth only
  GlProgram baked_catcher_;  // the ground catcher from its bake
};

}  // namespace arpipe
