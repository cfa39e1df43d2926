// Draws the virtual objects with per-row poses (see object_renderer.h).
#include "render/object_renderer.h"

#include <fmt/format.h>

#include <array>

namespace arpipe {
namespace {

constexpr std::string_view kShadingVertexShader = R"glsl(
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
uniform mat3 u_world_from_object_rotation;
out vec3 v_normal_world;

void main() {
  gl_Position = camera_to_clip(pose_camera_point(a_position));
  // The camera's motion does not turn the object in the world, so one normal serves every row.
  v_normal_world = u_world_from_object_rotation * a_normal;
}
)glsl";

constexpr std::string_view kShadingFragmentShader = R"glsl(#version 300 es
precision highp float;
in vec3 v_normal_world;
uniform vec4 u_base_color;       // linear, straight alpha
uniform vec3 u_light_direction;  // world frame, unit, towards the light
uniform vec3 u_light_color;
uniform vec3 u_ambient;
out vec4 out_color;              // linear, premultiplied alpha

void main() {
  vec3 normal = normalize(v_normal_world);
  if (!gl_FrontFacing) normal = -normal;  // the inside of an open mesh faces the other way
  float lambert = max(dot(normal, u_light_direction), 0.0);
  vec3 rgb = u_base_color.rgb * (u_ambient + u_light_color * lambert);
  out_color = vec4(rgb * u_base_color.a, u_base_color.a);
}
)glsl";

constexpr std::string_view kVelocityVertexShader = R"glsl(
layout(location = 0) in vec3 a_position;
out vec2 v_motion_px;
out float v_depth;

vec2 clip_to_pixel(vec4 clip) {  // pixel coordinates, centres at integers
  return (clip.xy / clip.w * 0.5 + 0.5) * u_image_size - 0.5;
}

void main() {
  vec3 mid = mid_camera_point(a_position);
  gl_Position = camera_to_clip(mid);
  vec4 start_clip = camera_to_clip(start_camera_point(a_position));
  vec4 end_clip = camera_to_clip(end_camera_point(a_position));
  // A point behind the camera at either end has no image path; it gets no blur rather than an
  // unbounded one.
  v_motion_px = start_clip.w > 0.0 && end_clip.w > 0.0 ? clip_to_pixel(end_clip) - clip_to_pixel(start_clip) : vec2(0.0);
  v_depth = mid.z;
}
)glsl";

constexpr std::string_view kVelocityFragmentShader = R"glsl(#version 300 es
precision highp float;
in vec2 v_motion_px;
in float v_depth;
out vec4 out_velocity;

void main() { out_velocity = vec4(v_motion_px, v_depth, 1.0); }
)glsl";

// Column-major, as glUniformMatrix3fv wants it without transposing.
std::array<float, 9> column_major(const Mat3& m) {
  std::array<float, 9> out{};
  for (size_t col = 0; col < 3; ++col)
    for (size_t row = 0; row < 3; ++row) out[col * 3 + row] = static_cast<float>(m[row][col]);
  return out;
}

void set_vec3(GLint location, const Vec3& v) {
  glUniform3f(location, static_cast<float>(v[0]), static_cast<float>(v[1]), static_cast<float>(v[2]));
}

std::string vertex_source(std::initializer_list<std::string_view> tables, std::string_view body) {
  std::string source = fmt::format("#version 300 es\nprecision highp float;\n{}\n", lens_projection_glsl());
  bool first = true;
  for (std::string_view table : tables) {
    source += row_poses_glsl(table, first);
    first = false;
  }
  source += body;
  return source;
}

// Image rows run down GL's y axis (lens_projection.h), which mirrors the winding: a triangle
// counter-clockwise seen from outside is clockwise in window coordinates.
void set_depth_state() {
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDisable(GL_BLEND);
  glDisable(GL_CULL_FACE);
  glFrontFace(GL_CW);
}

}  // namespace

ObjectRenderer::ObjectRenderer()
    : shading_("object shading", vertex_source({"pose"}, kShadingVertexShader), kShadingFragmentShader),
      velocity_("object velocity", vertex_source({"mid", "start", "end"}, kVelocityVertexShader), kVelocityFragmentShader) {}

void ObjectRenderer::draw(const LensUniforms& lens, const RowProjection& rows, const Lighting& lighting,
                          std::span<const ObjectAtInstant> objects) const {
  set_depth_state();
  set_lens_uniforms(shading_, lens);  // binds the program
  set_row_projection(shading_, rows);
  set_vec3(shading_.uniform("u_light_direction"), lighting.direction);
  set_vec3(shading_.uniform("u_light_color"), lighting.color);
  set_vec3(shading_.uniform("u_ambient"), lighting.ambient);
  const GLint world_from_object_rotation = shading_.uniform("u_world_from_object_rotation");
  const GLint base_color = shading_.uniform("u_base_color");
  for (const ObjectAtInstant& item : objects) {
    set_row_poses(shading_, "pose", item.poses, item.object->scale);
    const std::array<float, 9> rotation = column_major(item.object->T_world_object.rotation());
    glUniformMatrix3fv(world_from_object_rotation, 1, GL_FALSE, rotation.data());
    item.object->mesh->draw([&](const MeshPart& part) {
      const std::array<float, 4>& color = item.object->base_color ? *item.object->base_color : part.base_color;
      glUniform4f(base_color, color[0], color[1], color[2], color[3]);
    });
  }
}

void ObjectRenderer::draw_velocity(const LensUniforms& lens, const RowProjection& rows,
                                   std::span<const ObjectOverExposure> objects) const {
  set_depth_state();
  set_lens_uniforms(velocity_, lens);
  set_row_projection(velocity_, rows);
  for (const ObjectOverExposure& item : objects) {
    set_row_poses(velocity_, "start", item.start, item.object->scale);
    set_row_poses(velocity_, "mid", item.mid, item.object->scale);
    set_row_poses(velocity_, "end", item.end, item.object->scale);
    item.object->mesh->draw([](const MeshPart&) {});
  }
}

}  // namespace arpipe
