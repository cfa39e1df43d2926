// The render stage: draws the scene's virtual objects, seen from the tracked pose through the
// calibrated lens (render.lens: warped canvas, per-vertex distortion, or the undistorted pinhole
// core), into the shared virtual layer (linear, premultiplied alpha, depth-tested).
#include "render/render_stage.h"

#include <fmt/format.h>

#include <chrono>
#include <optional>

#include "core/log.h"
#include "core/pipeline/monotonic_clock.h"
#include "render/gl_error.h"
#include "render/lens_projection.h"
#include "render/lens_undistortion.h"
#include "render/projected_bounds.h"
#include "render/render_errors.h"

namespace arpipe {
namespace {

constexpr std::string_view kVertexShader = R"glsl(
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
uniform mat3 u_cam_from_object_linear;  // rotation times scale
uniform vec3 u_cam_from_object_translation;
uniform mat3 u_world_from_object_rotation;
out vec3 v_normal_world;

void main() {
  gl_Position = camera_to_clip(u_cam_from_object_linear * a_position + u_cam_from_object_translation);
  v_normal_world = u_world_from_object_rotation * a_normal;
}
)glsl";

constexpr std::string_view kFragmentShader = R"glsl(#version 300 es
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

// Covers the multisampled edge pixels and the bend of distorted edges between sampled points.
constexpr double kRectMarginPx = 2.0;

// Column-major, as glUniformMatrix3fv wants it without transposing.
std::array<float, 9> column_major(const Mat3& m, double scale) {
  std::array<float, 9> out{};
  for (size_t col = 0; col < 3; ++col)
    for (size_t row = 0; row < 3; ++row) out[col * 3 + row] = static_cast<float>(m[row][col] * scale);
  return out;
}

void set_vec3(GLint location, const Vec3& v) {
  glUniform3f(location, static_cast<float>(v[0]), static_cast<float>(v[1]), static_cast<float>(v[2]));
}

}  // namespace

RenderStage::RenderStage(std::shared_ptr<RenderSession> session) : session_(std::move(session)) {}

RenderStage::~RenderStage() {
  session_->try_make_current();
  objects_.clear();
  warp_pass_.reset();
  program_ = GlProgram();
}

void RenderStage::configure(const Config& config) {
  session_->ensure_context(config.render.egl_platform);
  session_->make_current();
  if (program_.id() == 0)
    program_ = GlProgram("object shading",
                         fmt::format("#version 300 es\nprecision highp float;\n{}\n{}", lens_projection_glsl(), kVertexShader),
                         kFragmentShader);
  std::vector<RenderObject> objects = load_render_objects(config);

  Settings settings;
  settings.enabled = config.render.enabled;
  settings.msaa_samples = config.render.msaa_samples;
  const double light_length = norm(config.render.light_direction);
  settings.light_direction = light_length > 0 ? (1.0 / light_length) * config.render.light_direction : Vec3{0, 0, 1};
  settings.light_color = config.render.light_color;
  settings.ambient = config.render.ambient;
  settings.lens = parse_lens_mode(config.render.lens);
  settings.lens_canvas_scale = config.render.lens_canvas_scale;

  // The warp's shader is compiled here rather than on the first frame that needs it.
  if (settings.lens == LensMode::Map && !warp_pass_)
    warp_pass_ = std::make_unique<LensWarpPass>(session_->layer().color_format());

  objects_ = std::move(objects);
  if (settings.lens_canvas_scale != settings_.lens_canvas_scale) warp_maps_.clear();
  settings_ = settings;
  last_error_.clear();
}

void RenderStage::prepare(const std::shared_ptr<const CameraModel>& camera_model) noexcept {
  if (!camera_model || !settings_.enabled || objects_.empty()) return;
  try {
    if (settings_.lens == LensMode::Map) warp_map(camera_model);
    if (settings_.lens == LensMode::Undistort) pinhole_core(camera_model);
  } catch (...) {
    // The cache keeps the error; the frames report it.
  }
}

std::shared_ptr<const LensWarpMap> RenderStage::warp_map(const std::shared_ptr<const CameraModel>& camera_model) {
  return warp_maps_.get(camera_model, [scale = settings_.lens_canvas_scale](const CameraModel& model) {
    return LensWarpMap(model, scale);
  });
}

std::shared_ptr<const CameraModel> RenderStage::pinhole_core(const std::shared_ptr<const CameraModel>& camera_model) {
  return pinhole_cores_.get(camera_model, [](const CameraModel& model) {
    check_lens_undistortable(model);
    return CameraModel::pinhole(model.fx(), model.fy(), model.cx(), model.cy(), model.width(), model.height());
  });
}

void RenderStage::process(FrameContext& ctx) noexcept {
  const auto start = std::chrono::steady_clock::now();
  ctx.virtual_layer_drawn = false;
  try {
    std::string skip;
    if (!settings_.enabled) skip = "render disabled";
    else if (objects_.empty()) skip = "no objects";
    else if (ctx.pose.state != TrackState::Tracking) skip = fmt::format("pose {}", track_state_name(ctx.pose.state));
    if (!skip.empty()) {
      ctx.record_timing(std::string(name()), milliseconds_since(start), std::move(skip));
      return;
    }
    draw(ctx);
    if (ctx.virtual_layer_drawn) {
      ctx.record_timing(std::string(name()), milliseconds_since(start));
      last_error_.clear();
    } else {
      ctx.record_timing(std::string(name()), milliseconds_since(start), "objects out of view");
    }
  } catch (const std::exception& e) {
    ctx.virtual_layer_drawn = false;
    if (last_error_ != e.what()) log::error("render: {}", e.what());
    last_error_ = e.what();
    ctx.record_timing(std::string(name()), milliseconds_since(start), fmt::format("error: {}", e.what()));
  } catch (...) {
    ctx.virtual_layer_drawn = false;
    ctx.record_timing(std::string(name()), milliseconds_since(start), "error: unknown exception");
  }
}

void RenderStage::draw(FrameContext& ctx) {
  if (!ctx.camera_model) throw RenderError("the frame has no camera model");
  const CameraModel& camera = *ctx.camera_model;
  if (camera.width() != ctx.camera.width || camera.height() != ctx.camera.height)
    throw RenderError(fmt::format("the camera frame is {}x{} but the camera model is for {}x{}", ctx.camera.width,
                                  ctx.camera.height, camera.width(), camera.height()));
  if (settings_.lens == LensMode::Vertex) check_lens_model_supported(camera);
  // What the output picture sees: the camera's lens, or its pinhole core when the composite
  // stage undistorts the camera frame.
  const std::shared_ptr<const CameraModel> core =
      settings_.lens == LensMode::Undistort ? pinhole_core(ctx.camera_model) : nullptr;
  const CameraModel& image_camera = core ? *core : camera;

  struct Visible {
    const RenderObject* object;
    SE3 T_cam_object;
  };
  std::vector<Visible> visible;
  PixelRect rect;  // in the output image
  for (const RenderObject& object : objects_) {
    const SE3 T_cam_object = ctx.pose.T_cam_world * object.T_world_object;
    if (std::optional<PixelRect> object_rect =
            projected_box_rect(image_camera, T_cam_object, object.bounds, kRectMarginPx)) {
      rect = rect.united(*object_rect);
      visible.push_back({&object, T_cam_object});
    }
  }
  if (visible.empty()) return;

  // "map": draw on the pinhole canvas, in the part of it that the output rectangle samples.
  std::shared_ptr<const LensWarpMap> warp;
  if (settings_.lens == LensMode::Map) {
    warp = warp_map(ctx.camera_model);
    if (warp->identity()) warp.reset();  // a pinhole lens: the canvas is the image
  }
  const LensUniforms lens = warp ? lens_uniforms(warp->canvas().model()) : lens_uniforms(image_camera);
  const PixelRect draw_rect = warp ? warp->canvas_rect_for(rect) : rect;

  session_->make_current();
  VirtualLayer& layer = session_->layer();
  layer.ensure(lens.width, lens.height, settings_.msaa_samples);
  layer.begin(draw_rect);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDisable(GL_BLEND);
  glDisable(GL_CULL_FACE);
  // Image rows run down GL's y axis (lens_projection.h), which mirrors the winding: a triangle
  // counter-clockwise seen from outside is clockwise in window coordinates.
  glFrontFace(GL_CW);

  set_lens_uniforms(program_, lens);  // binds the program
  set_vec3(program_.uniform("u_light_direction"), settings_.light_direction);
  set_vec3(program_.uniform("u_light_color"), settings_.light_color);
  set_vec3(program_.uniform("u_ambient"), settings_.ambient);
  const GLint cam_from_object_linear = program_.uniform("u_cam_from_object_linear");
  const GLint cam_from_object_translation = program_.uniform("u_cam_from_object_translation");
  const GLint world_from_object_rotation = program_.uniform("u_world_from_object_rotation");
  const GLint base_color = program_.uniform("u_base_color");
  for (const Visible& item : visible) {
    const std::array<float, 9> linear = column_major(item.T_cam_object.rotation(), item.object->scale);
    const std::array<float, 9> rotation = column_major(item.object->T_world_object.rotation(), 1.0);
    glUniformMatrix3fv(cam_from_object_linear, 1, GL_FALSE, linear.data());
    set_vec3(cam_from_object_translation, item.T_cam_object.translation());
    glUniformMatrix3fv(world_from_object_rotation, 1, GL_FALSE, rotation.data());
    item.object->mesh->draw([&](const MeshPart& part) {
      const std::array<float, 4>& color = item.object->base_color ? *item.object->base_color : part.base_color;
      glUniform4f(base_color, color[0], color[1], color[2], color[3]);
    });
  }
  layer.resolve(draw_rect);
  glDisable(GL_SCISSOR_TEST);
  GLuint drawn_texture = layer.texture();
  if (warp) {
    if (!warp_pass_) warp_pass_ = std::make_unique<LensWarpPass>(layer.color_format());
    warp_pass_->set_map(warp);
    warp_pass_->run(layer.texture(), rect);
    drawn_texture = warp_pass_->texture();
  }
  // The work is queued until something waits for it; waiting here keeps the stage timings honest.
  glFinish();
  check_gl("drawing the virtual layer");
  session_->drawn = {drawn_texture, camera.width(), camera.height(), rect};
  ctx.virtual_layer_drawn = true;
}

}  // namespace arpipe
