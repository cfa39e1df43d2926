// The simulator's "real world": ray casting with Embree, Lambertian and mirror surfaces, lights
// with shadow rays and the sky. See scene_shader.h; the physics is spelled out next to each part.
// Choices: a directional light's disc has radiance E / (pi sin^2 a), so that it gives exactly E
// to a surface facing it (E / solid angle is short by (1 + cos a) / 2); a mirror seen in a mirror
// shows the sky and light discs along its own reflection, cast no further; textures cover planes
// only; a mesh's albedo is the material's times its glTF part colour, shaded with its normals.
#include "capture/sim/scene_shader.h"
#include "core/geometry/math_constants.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <stdexcept>

#include "capture/sim/embree_scene.h"
#include "capture/sim/light_sampling.h"
#include "capture/sim/sim_object_mesh.h"
#include "capture/sim/sim_textures.h"
#include "core/scene/asset_error.h"
#include "core/scene/builtin_meshes.h"
#include "core/scene/gltf_loader.h"

namespace arpipe::sim {

namespace {


// Shadow and mirror rays start this far off the surface, along its normal (relative to the size of
// the coordinates and of the distance travelled, because triangles and Embree's traversal are in
// single precision: 1e-5 is ~80 float ulps). Within a metre of the origin that is 10 um, 1/100
// of a pixel at 0.5 m with f = 500 px, so contact shadows stay where they belong.
constexpr double kRayOffset = 1e-5;

double ray_offset(const Vec3& p, double t) {
  return kRayOffset * std::max({1.0, std::abs(p[0]), std::abs(p[1]), std::abs(p[2]), t});
}

Rgb operator*(const Rgb& a, const Rgb& b) { return {a[0] * b[0], a[1] * b[1], a[2] * b[2]}; }
Rgb operator*(double s, const Rgb& a) { return {s * a[0], s * a[1], s * a[2]}; }
Rgb& operator+=(Rgb& a, const Rgb& b) {
  a[0] += b[0];
  a[1] += b[1];
  a[2] += b[2];
  return a;
}

Vec3 column(const Mat3& m, int c) { return {m[0][size_t(c)], m[1][size_t(c)], m[2][size_t(c)]}; }

struct Surface {
  enum class Kind { Plane, Sphere, Mesh, Light };
  Kind kind = Kind::Plane;
  bool mirror = false;
  Rgb albedo{0, 0, 0};  // diffuse albedo, or the mirror's reflectance
  // Lambertian: the Blinn-Phong highlight's reflectance and exponent (0: none).
  double specular = 0;
  double shininess = 0;
  std::optional<PlaneTexture> texture;
  // Plane: its frame, for texture coordinates.
  Vec3 centre{0, 0, 0}, x_axis{1, 0, 0}, y_axis{0, 1, 0};
  double width = 0, height = 0;
  // Mesh: smooth-shading normals (world) per vertex, albedo per triangle (material x part colour).
  std::vector<float> normals;
  std::vector<uint32_t> indices;
  std::vector<Rgb> triangle_albedo;
  // Light: the radiance of its surface.
  Rgb emitted{0, 0, 0};
  bool is_virtual = false;  // an object only the ground-truth composite shows
};

struct DirectionalLight {
  Vec3 to_light{0, 0, 1};
  Frame3 frame;
  double one_minus_cos = 0;  // of the disc's half angle; 0: a point-like light (hard shadows)
  // Per-sample weight of a direction drawn uniformly in the disc: L_disc * solid angle.
  Rgb sample_weight{0, 0, 0};
  Rgb disc_radiance{0, 0, 0};  // what a ray that misses everything sees inside the disc
};

struct PointLight {
  Vec3 position{0, 0, 0};
  Rgb intensity{0, 0, 0};  // W/sr
};

struct SphereLight {
  SphereShape sphere;
  Rgb radiance{0, 0, 0};
  uint32_t shape = 0;
};

void check_object(bool ok, const SimObject& object, const std::string& what) {
  if (!ok) throw std::invalid_argument(fmt::format("object \"{}\": {}", object.name, what));
}

void check_light(bool ok, const SimLight& light, const std::string& what) {
  if (!ok) throw std::invalid_argument(fmt::format("light \"{}\": {}", light.name, what));
}

}  // namespace

struct SceneShader::Impl {
  EmbreeScene scene;
  std::vector<Surface> surfaces;  // by shape id
  EnvironmentMap environment;
  std::vector<DirectionalLight> directional;
  std::vector<PointLight> points;
  std::vector<SphereLight> spheres;

  explicit Impl(const SimEnvironment& env) : environment(env) {}

  void add_object(const SimObject& object) {
    Surface surface;
    const SimMaterial& material = object.material;
    surface.mirror = material.kind == SimMaterial::Kind::Mirror;
    surface.albedo = material.albedo;
    surface.is_virtual = object.is_virtual;
    check_object(material.specular >= 0 && material.specular <= 1, object,
                 fmt::format("specular must be in [0, 1], got {}", material.specular));
    check_object(material.specular == 0 || !surface.mirror, object, "a mirror has no glossy highlight (specular)");
    check_object(material.specular == 0 || (material.shininess >= 1 && std::isfinite(material.shininess)), object,
                 fmt::format("shininess must be a finite number >= 1, got {}", material.shininess));
    surface.specular = material.specular;
    surface.shininess = material.shininess;
    check_object(material.texture.kind == SimTexture::Kind::None || object.shape == SimObject::Shape::Plane, object,
                 "textures cover planes only");
    check_object(material.texture.kind == SimTexture::Kind::None || !surface.mirror, object,
                 "a mirror cannot have a texture");
    const ShapeRole role{true, object.casts_shadows};
    const Mat3& R = object.T_world_object.rotation();
    const Vec3& origin = object.T_world_object.translation();
    uint32_t id = 0;
    switch (object.shape) {
      case SimObject::Shape::Plane: {
        check_object(
            object.width_m > 0 && object.height_m > 0, object,
            fmt::format("a plane needs a positive width and height, got {} x {} m", object.width_m, object.height_m));
        surface.kind = Surface::Kind::Plane;
        surface.centre = origin;
        surface.x_axis = column(R, 0);
        surface.y_axis = column(R, 1);
        surface.width = object.width_m;
        surface.height = object.height_m;
        if (material.texture.kind != SimTexture::Kind::None) surface.texture.emplace(material, object.name);
        id = scene.add_rectangle({origin, surface.x_axis, surface.y_axis, object.width_m / 2, object.height_m / 2},
                                 role);
        break;
      }
      case SimObject::Shape::Sphere:
        check_object(object.radius_m > 0, object,
                     fmt::format("a sphere needs a positive radius, got {}", object.radius_m));
        surface.kind = Surface::Kind::Sphere;
        id = scene.add_sphere({origin, object.radius_m}, role);
        break;
      case SimObject::Shape::Mesh: {
        const Mesh mesh = sim_object_mesh(object);
        surface.kind = Surface::Kind::Mesh;
        std::vector<float> positions(mesh.positions.size());
        surface.normals.resize(mesh.positions.size());
        for (size_t v = 0; v < mesh.vertex_count(); ++v) {
          const float* p = &mesh.positions[v * 3];
          const Vec3 world = object.T_world_object * (object.mesh_scale * Vec3{p[0], p[1], p[2]});
          Vec3 n{0, 0, 0};  // none: shaded with the geometric normal
          if (mesh.normals.size() == mesh.positions.size()) {
            const float* m = &mesh.normals[v * 3];
            n = mat_mul(R, Vec3{m[0], m[1], m[2]});
          }
          for (size_t c = 0; c < 3; ++c) {
            positions[v * 3 + c] = float(world[c]);
            surface.normals[v * 3 + c] = float(n[c]);
          }
        }
        surface.indices = mesh.indices;
        surface.triangle_albedo.assign(mesh.triangle_count(), material.albedo);
        for (const MeshPart& part : mesh.parts) {
          const Rgb tint{part.base_color[0], part.base_color[1], part.base_color[2]};
          for (size_t t = part.first_index / 3;
               t < (size_t(part.first_index) + part.index_count) / 3 && t < surface.triangle_albedo.size(); ++t)
            surface.triangle_albedo[t] = material.albedo * tint;
        }
        id = scene.add_triangles(std::move(positions), mesh.indices, role);
        break;
      }
    }
    add_surface(id, std::move(surface));
  }

  void add_surface(uint32_t id, Surface surface) {
    if (surfaces.size() <= id) surfaces.resize(id + 1);
    surfaces[id] = std::move(surface);
  }

  void add_light(const SimLight& light) {
    for (double c : light.color) check_light(std::isfinite(c) && c >= 0, light, "colour must be finite and >= 0");
    switch (light.kind) {
      case SimLight::Kind::Directional: {
        check_light(norm(light.direction_to_light) > 0, light, "direction_to_light must not be zero");
        check_light(light.irradiance >= 0, light, fmt::format("irradiance must be >= 0, got {}", light.irradiance));
        check_light(light.angular_diameter_rad >= 0 && light.angular_diameter_rad < kPi, light,
                    fmt::format("angular diameter must be in [0, pi), got {} rad", light.angular_diameter_rad));
        DirectionalLight d;
        d.to_light = normalized(light.direction_to_light);
        d.frame = frame_around(d.to_light);
        d.one_minus_cos = one_minus_cos(light.angular_diameter_rad / 2);
        const Rgb irradiance = light.irradiance * light.color;
        if (d.one_minus_cos > 0) {
          // A disc of uniform radiance L gives a surface facing it E = L pi sin^2(a); sampling
          // directions uniformly in the disc's solid angle 2 pi (1 - cos a), each weighs
          // L * solid angle = E * 2 / (1 + cos a), so a facing surface receives exactly E.
          const double sin2 = d.one_minus_cos * (2 - d.one_minus_cos);
          d.disc_radiance = (1.0 / (kPi * sin2)) * irradiance;
          d.sample_weight = (2.0 / (2.0 - d.one_minus_cos)) * irradiance;
        } else {
          d.sample_weight = irradiance;  // a point-like light: invisible to rays
        }
        directional.push_back(d);
        break;
      }
      case SimLight::Kind::Point:
        check_light(light.intensity >= 0, light, fmt::format("intensity must be >= 0, got {}", light.intensity));
        points.push_back({light.position, light.intensity * light.color});
        break;
      case SimLight::Kind::Sphere: {
        check_light(light.intensity >= 0, light, fmt::format("intensity must be >= 0, got {}", light.intensity));
        check_light(light.radius_m > 0, light, fmt::format("a sphere light needs radius > 0, got {}", light.radius_m));
        SphereLight s;
        s.sphere = {light.position, light.radius_m};
        s.radiance = (light.intensity / (kPi * light.radius_m * light.radius_m)) * light.color;
        s.shape = scene.add_sphere(s.sphere, ShapeRole{true, true});
        Surface surface;
        surface.kind = Surface::Kind::Light;
        surface.emitted = s.radiance;
        add_surface(s.shape, std::move(surface));
        spheres.push_back(s);
        break;
      }
    }
  }

  // What a ray that leaves the scene sees: the sky, plus the discs of directional lights.
  Rgb sky(const Vec3& d) const {
    Rgb out = environment.radiance(d);
    for (const DirectionalLight& light : directional)
      if (light.one_minus_cos > 0 && 1.0 - dot(d, light.to_light) <= light.one_minus_cos) out += light.disc_radiance;
    return out;
  }

  Rgb diffuse_reflectance(const Surface& s, const ShapeHit& hit, const Vec3& p) const {
    if (s.kind == Surface::Kind::Mesh) return s.triangle_albedo[hit.triangle];
    if (!s.texture) return s.albedo;
    const Vec3 local = p - s.centre;
    return s.texture->reflectance(dot(local, s.x_axis) / s.width + 0.5, 0.5 - dot(local, s.y_axis) / s.height);
  }

  Vec3 shading_normal(const Surface& s, const ShapeHit& hit, const Vec3& facing) const {
    if (s.kind != Surface::Kind::Mesh) return facing;
    const uint32_t* tri = &s.indices[size_t(hit.triangle) * 3];
    Vec3 n{0, 0, 0};
    const double w[3] = {1 - hit.b1 - hit.b2, hit.b1, hit.b2};
    for (int k = 0; k < 3; ++k) {
      const float* m = &s.normals[size_t(tri[k]) * 3];
      n = n + w[k] * Vec3{m[0], m[1], m[2]};
    }
    const double length = norm(n);
    if (!(length > 0)) return facing;
    n = (1.0 / length) * n;
    return dot(n, facing) >= 0 ? n : -1.0 * n;
  }

  // A Lambertian point p with geometric normal n facing the viewer, reached after travelling t
  // along d: albedo / pi * sum of the lights' irradiance (each with its own shadow ray), plus the
  // sky's light from one cosine-weighted direction (the sky alone: directional discs are lights
  // above). A glossy surface (specular > 0) adds the normalised Blinn-Phong lobe
  // specular * (m + 8) / (8 pi) * (ns.h)^m for each light's sample direction w, h the unit half
  // vector of w and the view direction -d, weighted by the same irradiance: the highlights of the
  // lights, in their own colour. The sky gets no highlight.
  Rgb shade_diffuse(const Surface& s, const ShapeHit& hit, const Vec3& p, const Vec3& n, const Vec3& d,
                    SampleRng& rng) const {
    const Rgb albedo = diffuse_reflectance(s, hit, p);
    const Vec3 ns = shading_normal(s, hit, n);
    const Vec3 o = p + ray_offset(p, hit.t) * n;
    const bool glossy = s.specular > 0;
    const Vec3 view = -1.0 * d;
    Rgb highlight{0, 0, 0};  // sum of (ns.h)^m times each light's irradiance
    const auto add_highlight = [&](const Vec3& w, const Rgb& irradiance_from_w) {
      const Vec3 h = w + view;
      const double length = norm(h);
      if (!(length > 0)) return;
      const double c = dot(ns, h) / length;
      if (c > 0) highlight += std::pow(c, s.shininess) * irradiance_from_w;
    };
    Rgb irradiance{0, 0, 0};
    for (const DirectionalLight& light : directional) {
      Vec3 w = light.to_light;
      if (light.one_minus_cos > 0) {
        const double u1 = rng.uniform(), u2 = rng.uniform();
        w = sample_cone(light.frame, light.one_minus_cos, u1, u2);
      }
      const double c = dot(ns, w);
      if (c > 0 && dot(n, w) > 0 && !scene.occluded(o, w)) {
        irradiance += c * light.sample_weight;
        if (glossy) add_highlight(w, c * light.sample_weight);
      }
    }
    for (const PointLight& light : points) {
      const Vec3 to_light = light.position - p;
      const double d2 = dot(to_light, to_light);
      const Vec3 w = (1.0 / std::sqrt(d2)) * to_light;
      const double c = dot(ns, w);
      if (c > 0 && dot(n, w) > 0 && !scene.occluded(o, w, 0, std::sqrt(d2))) {
        irradiance += (c / d2) * light.intensity;
        if (glossy) add_highlight(w, (c / d2) * light.intensity);
      }
    }
    for (const SphereLight& light : spheres) {
      // One direction uniform in the cone the sphere subtends: E ~ L * solid angle * cos.
      const double u1 = rng.uniform(), u2 = rng.uniform();
      const SphereCone cone = sphere_cone(p, light.sphere.centre, light.sphere.radius);
      if (!cone.outside) continue;
      const Vec3 w = sample_cone(frame_around(cone.axis), cone.one_minus_cos, u1, u2);
      const double c = dot(ns, w);
      if (!(c > 0 && dot(n, w) > 0)) continue;
      const double t_light = intersect_sphere(o, w, light.sphere, 0, kInfinity);
      if (!scene.occluded(o, w, 0, t_light, light.shape)) {
        irradiance += (c * cone_solid_angle(cone.one_minus_cos)) * light.radiance;
        if (glossy) add_highlight(w, (c * cone_solid_angle(cone.one_minus_cos)) * light.radiance);
      }
    }
    Rgb out = (1.0 / kPi) * (albedo * irradiance);
    if (glossy) out += (s.specular * (s.shininess + 8) / (8 * kPi)) * highlight;
    if (!environment.is_black()) {
      // Cosine-weighted: the pdf cos/pi cancels the BRDF's 1/pi and the cosine.
      const double u1 = rng.uniform(), u2 = rng.uniform();
      const Vec3 w = sample_cosine_hemisphere(frame_around(ns), u1, u2);
      if (dot(n, w) > 0 && !scene.occluded(o, w)) out += albedo * environment.radiance(w);
    }
    return out;
  }

  // first_hit_virtual, when given, says whether the first surface along the ray is a virtual object.
  Rgb trace(const Vec3& origin, const Vec3& d, SampleRng& rng, bool* first_hit_virtual = nullptr) const {
    const ShapeHit hit = scene.intersect(origin, d);
    if (first_hit_virtual != nullptr) *first_hit_virtual = hit.hit() && hit.shape < surfaces.size() && surfaces[hit.shape].is_virtual;
    if (!hit.hit()) return sky(d);
    const Surface& s = surfaces[hit.shape];
    if (s.kind == Surface::Kind::Light) return s.emitted;
    const Vec3 p = origin + hit.t * d;
    const Vec3 n = dot(hit.normal, d) < 0 ? hit.normal : -1.0 * hit.normal;
    if (!s.mirror) return shade_diffuse(s, hit, p, n, d, rng);

    // One mirror bounce. A mirror seen in the mirror shows the sky (and light discs) along its own
    // reflection, cast no further: enough for light probes, which never face each other closely.
    const Vec3 r = d - (2 * dot(d, n)) * n;
    const Vec3 o2 = p + ray_offset(p, hit.t) * n;
    const ShapeHit hit2 = scene.intersect(o2, r);
    if (!hit2.hit()) return s.albedo * sky(r);
    const Surface& s2 = surfaces[hit2.shape];
    if (s2.kind == Surface::Kind::Light) return s.albedo * s2.emitted;
    const Vec3 p2 = o2 + hit2.t * r;
    const Vec3 n2 = dot(hit2.normal, r) < 0 ? hit2.normal : -1.0 * hit2.normal;
    if (s2.mirror) return (s.albedo * s2.albedo) * sky(r - (2 * dot(r, n2)) * n2);
    return s.albedo * shade_diffuse(s2, hit2, p2, n2, r, rng);
  }
};

SceneShader::SceneShader(const SimScene& scene, bool include_virtual)
    : impl_(std::make_unique<Impl>(scene.environment)) {
  for (const SimObject& object : scene.objects)
    if (include_virtual || !object.is_virtual) impl_->add_object(object);
  for (const SimLight& light : scene.lights) impl_->add_light(light);
  impl_->scene.commit();
}

SceneShader::~SceneShader() = default;

Rgb SceneShader::radiance(const Vec3& origin, const Vec3& dir, SampleRng& rng) const {
  return impl_->trace(origin, normalized(dir), rng);
}

Rgb SceneShader::radiance(const Vec3& origin, const Vec3& dir, SampleRng& rng, bool& first_hit_virtual) const {
  return impl_->trace(origin, normalized(dir), rng, &first_hit_virtual);
}

bool SceneShader::sees_virtual_object(const Vec3& origin, const Vec3& dir) const {
  const ShapeHit hit = impl_->scene.intersect(origin, normalized(dir));
  return hit.hit() && hit.shape < impl_->surfaces.size() && impl_->surfaces[hit.shape].is_virtual;
}

}  // namespace arpipe::sim
