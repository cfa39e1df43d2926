// The fast blur option: one render at mid-exposure plus per-pixel motion, gathered along the
// neighbourhood's dominant motion (after McGuire et al. 2012), as a time average without background.
#include "render/blur/velocity_blur_pass.h"

#include <algorithm>

#include "render/gl/fullscreen_triangle.h"
#include "render/gl/gl_error.h"
#include "render/gl/render_errors.h"

namespace arpipe {
namespace {

// Tile size of the motion maximum. A surface point blurs at most half its motion either way, and
// the 3x3 neighbour maximum sees every tile within one tile of a pixel's own, so motions up to
// 2 * kTile = 64 px reach every pixel they cover; longer trails are cut at that distance.
constexpr int kTile = 32;

// Pass 1: per kTile x kTile tile, the motion of largest length.
constexpr std::string_view kTileMaxShader = R"glsl(#version 300 es
precision highp float;
uniform highp sampler2D u_velocity;
uniform int u_tile;
out vec4 out_max;

void main() {
  ivec2 size = textureSize(u_velocity, 0);
  ivec2 start = ivec2(gl_FragCoord.xy) * u_tile;
  ivec2 end = min(start + u_tile, size);
  vec2 best = vec2(0.0);
  for (int y = start.y; y < end.y; ++y)
    for (int x = start.x; x < end.x; ++x) {
      vec2 v = texelFetch(u_velocity, ivec2(x, y), 0).xy;
      if (dot(v, v) > dot(best, best)) best = v;
    }
  out_max = vec4(best, 0.0, 0.0);
}
)glsl";

// Pass 2: the largest of the 3 x 3 tile maxima around each tile.
constexpr std::string_view kNeighbourMaxShader = R"glsl(#version 300 es
precision highp float;
uniform highp sampler2D u_tile_max;
out vec4 out_max;

void main() {
  ivec2 tile = ivec2(gl_FragCoord.xy);
  ivec2 last = textureSize(u_tile_max, 0) - 1;
  vec2 best = vec2(0.0);
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      vec2 v = texelFetch(u_tile_max, clamp(tile + ivec2(dx, dy), ivec2(0), last), 0).xy;
      if (dot(v, v) > dot(best, best)) best = v;
    }
  out_max = vec4(best, 0.0, 0.0);
}
)glsl";

// Pass 3, the gather. The model: the layer at exposure time u in [-1/2, 1/2] is the mid-exposure
// render with each surface point moved by v u (v: its motion over the exposure). The render is
// read as a continuous image, each pixel's colour over its unit square; the output is the time
// average at the pixel centre X, as an accumulation buffer of point-sampled renders gives. A
// source point at distance d from X with motion v sits on X during the part 1/|v| of the exposure
// per unit of path, when X is on its path (d <= |v|/2), so
//   out(X) = integral over source points Y of colour(Y) / |v_Y| * [|X - Y| <= |v_Y| / 2].
// For a solid region in uniform translation this is exactly the box filter of length |v|: a
// linear ramp of length |v| at each edge, alpha conserved.
// The integral runs along the neighbourhood-maximum motion v_N (the line where, for the usual
// rigid object, the sources of X lie; other directions are missed, as in McGuire et al.), split:
//   - X's own pixel (|s| < 1/2 along the line): its own colour, on X for min(1, 1/|v_X|) of the
//     exposure (its path of length |v_X| inside a unit pixel);
//   - the rest out to |v_N|/2 on both sides: `samples` segments of length h, each read once at its
//     midpoint (bilinear colour; motion and depth bilinear too, divided by the bilinear coverage a
//     so that an edge tap keeps the surface's own motion), weighted by the exact integral of
//     1/|v_Y| over the part of the segment within |v_Y|/2 of X. With v_Y = v_N the segments tile
//     the line and the weights sum to 1 - 1/|v_N| with the own pixel's 1/|v_N|: mass conserved.
// Like McGuire's cone and cylinder tests, distance is measured as |X - Y|, not along v_Y.
// Depth: a source behind X's own surface (soft step over kDepthSoftness metres) is hidden while
// that surface is still on X: its weight loses the overlap of its time on X (|u| from
// (s - h/2)/|v_Y| on) with the own surface's (|u| < min(1, 1/|v_X|)/2). Surfaces moving together
// never overlap in time, so this only acts between surfaces that move differently. Where several
// surfaces in front still add up to more than full coverage, the sum is normalised to alpha 1.
// Pixels whose neighbourhood moves less than half a pixel keep their own colour (below a pixel of
// motion the model changes nothing at axis-aligned edges anyway).
constexpr std::string_view kGatherShader = R"glsl(#version 300 es
precision highp float;
uniform highp sampler2D u_color;
uniform highp sampler2D u_velocity;
uniform highp sampler2D u_neighbour_max;
uniform int u_tile;
uniform int u_taps_per_side;
out vec4 out_color;

const float kDepthSoftness = 0.01;

void main() {
  ivec2 pixel = ivec2(gl_FragCoord.xy);
  vec4 own_color = texelFetch(u_color, pixel, 0);
  vec2 v_n = texelFetch(u_neighbour_max, pixel / u_tile, 0).xy;
  float v_n_length = length(v_n);
  if (v_n_length < 0.5) {
    out_color = own_color;
    return;
  }
  vec4 own = texelFetch(u_velocity, pixel, 0);
  float own_time = min(1.0, 1.0 / max(length(own.xy), 1e-6));
  vec4 sum = own_color * own_time;
  float reach = 0.5 * v_n_length - 0.5;
  if (reach > 0.0) {
    vec2 size = vec2(textureSize(u_color, 0));
    vec2 direction = v_n / v_n_length;
    float h = reach / float(u_taps_per_side);
    for (int k = 0; k < u_taps_per_side; ++k) {
      float s = 0.5 + (float(k) + 0.5) * h;
      for (int side = -1; side <= 1; side += 2) {
        vec2 uv = (gl_FragCoord.xy + float(side) * s * direction) / size;
        vec4 velocity = texture(u_velocity, uv);
        if (velocity.a <= 0.0) continue;  // nothing there: its colour is transparent too
        float speed = length(velocity.xy) / velocity.a;
        float near_end = s - 0.5 * h;
        float covered = clamp(0.5 * speed - near_end, 0.0, h);  // of the segment, within |v_Y|/2
        if (covered <= 0.0) continue;
        float weight = covered / speed;
        float behind = clamp((velocity.z / velocity.a - own.z) / kDepthSoftness, 0.0, 1.0) * own.a;
        float hidden = clamp(0.5 * own_time - near_end / speed, 0.0, weight);
        sum += texture(u_color, uv) * (weight - behind * hidden);
      }
    }
  }
  out_color = sum.a > 1.0 ? sum / sum.a : sum;
}
)glsl";

void draw_full_screen(GLuint vertex_array) {
  glBindVertexArray(vertex_array);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glBindVertexArray(0);
}

}  // namespace

VelocityBlurPass::VelocityBlurPass(GLenum output_format)
    : output_format_(output_format),
      linear_sampler_(GlSampler::create()),
      tile_max_program_("velocity blur tile max", kFullScreenTriangleVertexShader, kTileMaxShader),
      neighbour_max_program_("velocity blur neighbour max", kFullScreenTriangleVertexShader, kNeighbourMaxShader),
      gather_program_("velocity blur gather", kFullScreenTriangleVertexShader, kGatherShader),
      empty_vertex_array_(GlVertexArray::create()) {
  glSamplerParameteri(linear_sampler_.get(), GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glSamplerParameteri(linear_sampler_.get(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glSamplerParameteri(linear_sampler_.get(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glSamplerParameteri(linear_sampler_.get(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glUseProgram(tile_max_program_.id());
  glUniform1i(tile_max_program_.uniform("u_velocity"), 0);
  glUniform1i(tile_max_program_.uniform("u_tile"), kTile);
  glUseProgram(neighbour_max_program_.id());
  glUniform1i(neighbour_max_program_.uniform("u_tile_max"), 0);
  glUseProgram(gather_program_.id());
  glUniform1i(gather_program_.uniform("u_color"), 0);
  glUniform1i(gather_program_.uniform("u_velocity"), 1);
  glUniform1i(gather_program_.uniform("u_neighbour_max"), 2);
  glUniform1i(gather_program_.uniform("u_tile"), kTile);
  check_gl("setting up the velocity blur pass");
}

void VelocityBlurPass::ensure_targets(int width, int height) {
  if (width == width_ && height == height_ && output_texture_) return;
  tiles_x_ = (width + kTile - 1) / kTile;
  tiles_y_ = (height + kTile - 1) / kTile;
  // Motions in pixels, half floats (as the velocity input): RG16F renders wherever RGBA16F does
  // (EXT_color_buffer_half_float / _float).
  const auto make_target = [](GLenum format, int w, int h, GlTexture& texture, GlFramebuffer& framebuffer,
                              const char* what) {
    texture = create_texel_texture(format, w, h);
    framebuffer = create_framebuffer_for(texture.get());
    check_framebuffer_complete(what);
  };
  make_target(GL_RG16F, tiles_x_, tiles_y_, tile_max_texture_, tile_max_framebuffer_, "velocity blur tile max");
  make_target(GL_RG16F, tiles_x_, tiles_y_, neighbour_max_texture_, neighbour_max_framebuffer_,
              "velocity blur neighbour max");
  make_target(output_format_, width, height, output_texture_, output_framebuffer_, "velocity blur output");
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  width_ = width, height_ = height;
}

void VelocityBlurPass::run(GLuint color, GLuint velocity, int width, int height, const PixelRect& rect,
                           int samples) {
  if (width <= 0 || height <= 0) throw RenderError("velocity blur pass: empty image size");
  ensure_targets(width, height);
  if (rect.empty()) return;
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_BLEND);
  glEnable(GL_SCISSOR_TEST);

  // The tiles under rect and one ring around it (the neighbour maximum reads them).
  const int tx0 = std::max(rect.x / kTile - 1, 0), ty0 = std::max(rect.y / kTile - 1, 0);
  const int tx1 = std::min((rect.right() - 1) / kTile + 2, tiles_x_);
  const int ty1 = std::min((rect.bottom() - 1) / kTile + 2, tiles_y_);
  glViewport(0, 0, tiles_x_, tiles_y_);
  glScissor(tx0, ty0, tx1 - tx0, ty1 - ty0);
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, velocity);
  glBindFramebuffer(GL_FRAMEBUFFER, tile_max_framebuffer_.get());
  glUseProgram(tile_max_program_.id());
  draw_full_screen(empty_vertex_array_.get());

  glBindTexture(GL_TEXTURE_2D, tile_max_texture_.get());
  glBindFramebuffer(GL_FRAMEBUFFER, neighbour_max_framebuffer_.get());
  glUseProgram(neighbour_max_program_.id());
  draw_full_screen(empty_vertex_array_.get());

  glBindTexture(GL_TEXTURE_2D, color);
  glBindSampler(0, linear_sampler_.get());
  glActiveTexture(GL_TEXTURE1);
  glBindTexture(GL_TEXTURE_2D, velocity);
  glBindSampler(1, linear_sampler_.get());
  glActiveTexture(GL_TEXTURE2);
  glBindTexture(GL_TEXTURE_2D, neighbour_max_texture_.get());
  glActiveTexture(GL_TEXTURE0);
  glViewport(0, 0, width, height);
  glScissor(rect.x, rect.y, rect.width, rect.height);
  glBindFramebuffer(GL_FRAMEBUFFER, output_framebuffer_.get());
  glUseProgram(gather_program_.id());
  // Odd counts round up: the taps go in pairs, one each side of the pixel.
  glUniform1i(gather_program_.uniform("u_taps_per_side"), (std::clamp(samples, 2, kMaxSamples) + 1) / 2);
  draw_full_screen(empty_vertex_array_.get());

  glBindSampler(0, 0);
  glBindSampler(1, 0);
  glDisable(GL_SCISSOR_TEST);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  check_gl("velocity blur pass");
}

}  // namespace arpipe
