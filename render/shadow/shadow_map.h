// The shadow map of the directional light: depth (hard, PCF, PCSS) or blurred depth moments (VSM,
// float or the seed's 8-bit packing), rendered from the light's fitted orthographic box, and the
// uniforms that the shading pass needs to look it up. Rendered again only when the light, the
// objects or the settings change.
#pragma once

#include <array>
#include <optional>
#include <span>

#include "core/config/config.h"
#include "render/gl/egl_context.h"
#include "render/gl/gl_objects.h"
#include "render/gl/gl_program.h"
#include "render/uploaded_objects.h"
#include "render/shadow/shadow_frustum.h"
#include "core/config/shadow_method.h"

namespace arpipe {

// Everything the shading pass needs to read the shadow map (see shadow_lookup_glsl.h).
struct ShadowLookup {
  ShadowMethod method = ShadowMethod::Off;
  GLuint texture = 0;
  std::array<float, 16> clip_from_world{};
  std::array<float, 4> depth_plane{};  // world point -> depth in [0, 1]
  bool local = false;              // a perspective map from a lamp at a known place
  float near_m = 0, range_m = 0;   // local: the depth range in metres
  float texel = 0;                 // 1 / map size
  float bias = 0;                  // depth units
  float pcf_radius_texels = 0;     // pcf: half the kernel width
  // pcss: directional, penumbra radius in texels per unit of depth between blocker and receiver;
  // local, the k of shadow_map.cpp's formula; and the most the blocker search looks around.
  float penumbra_texels_per_depth = 0;
  float max_search_texels = 0;
  float vsm_min_variance = 0;
  float vsm_bleed_reduction = 0;
};

class ShadowMapPass {
 public:
  // Compiles the programs the method needs; needs a current context. Throws RenderError.
  ShadowMapPass(const EglContext& context, const ShadowConfig& config);
  const ShadowConfig& config() const { return config_; }

  // Renders the casters' shadow map for this frustum unless the last one was made from the same
  // frustum and casters (then reused: returns false). angular_diameter_rad: the light's size (pcss).
  bool render(const ShadowFrustum& frustum, std::span<const UploadedObject* const> casters, double angular_diameter_rad);
  const ShadowLookup& lookup() const { return lookup_; }
  void invalidate() { have_key_ = false; }  // the next render draws again

 private:
  struct Key {
    Mat3 R{};
    std::array<double, 3> min{}, max{};
    std::vector<std::array<double, 7>> casters;  // translation, rotation vector, scale
    double angular_diameter = 0;
    std::array<double, 6> local{};  // light position, near, far, tan of the half angle
    bool operator==(const Key&) const = default;
  };
  void draw_casters(const GlProgram& program, const ShadowFrustum& frustum, std::span<const UploadedObject* const> casters);
  void blur_moments();

  ShadowConfig config_;
  ShadowMethod method_;
  GLenum moments_format_ = 0;
  GlProgram depth_program_;      // hard, pcf, pcss: depth only
  GlProgram moments_program_;    // vsm: (z, z^2), float or packed
  GlProgram blur_program_;       // vsm: one separable Gaussian pass
  GlTexture map_;                // depth texture, or the moments
  GlTexture blur_scratch_;       // vsm: between the two blur passes
  GlRenderbuffer depth_buffer_;  // vsm: depth test while writing moments
  GlFramebuffer framebuffer_;
  GlFramebuffer scratch_framebuffer_;
  GlVertexArray empty_vertex_array_;
  ShadowLookup lookup_;
  Key key_;
  bool have_key_ = false;
};

}  // namespace arpipe
