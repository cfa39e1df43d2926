// SceneShader against analytic radiometry and geometry: Lambertian shading under each kind of
// light, the sky's ambient light, soft-shadow penumbrae, exact mirror reflections, textures placed
// by the plane's frame, virtual and shadowless objects, asset errors and determinism.
#include "capture/sim/scene_shader.h"

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <fstream>
#include <functional>
#include <numbers>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>
#include <thread>

#include "capture/sim/light_sampling.h"
#include "core/scene/asset_error.h"
#include "core/track/tag_family.h"
#include "tests/scene/gltf_test_files.h"
#include "tests/sim/sim_test_support.h"

// apriltag.h after the project headers: its family struct is what tag_family.h forward-declares.
#include <apriltag/apriltag.h>

namespace arpipe::sim {
namespace {

namespace fs = std::filesystem;
constexpr double kPi = std::numbers::pi;

fs::path temp_dir(const std::string& name) {
  const fs::path dir =
      fs::path(::testing::TempDir()) / ("arpipe_scene_shader_" + name + "_" + std::to_string(getpid()));
  fs::create_directories(dir);
  return dir;
}

SE3 at(const Vec3& t, const Mat3& R = identity3()) { return SE3(R, t); }

// Rotation about z by angle (radians).
Mat3 rot_z(double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  return {{{c, -s, 0}, {s, c, 0}, {0, 0, 1}}};
}

SimObject plane(const std::string& name, const SE3& pose, double width, double height, const Rgb& albedo) {
  SimObject o;
  o.name = name;
  o.shape = SimObject::Shape::Plane;
  o.T_world_object = pose;
  o.width_m = width;
  o.height_m = height;
  o.material.albedo = albedo;
  return o;
}

SimObject sphere(const std::string& name, const Vec3& centre, double radius, const Rgb& albedo, bool mirror = false) {
  SimObject o;
  o.name = name;
  o.shape = SimObject::Shape::Sphere;
  o.T_world_object = at(centre);
  o.radius_m = radius;
  o.material.albedo = albedo;
  if (mirror) o.material.kind = SimMaterial::Kind::Mirror;
  return o;
}

SimLight directional(const Vec3& to_light, double irradiance, double diameter_rad = 0, const Rgb& color = {1, 1, 1}) {
  SimLight l;
  l.name = "sun";
  l.kind = SimLight::Kind::Directional;
  l.direction_to_light = normalized(to_light);
  l.irradiance = irradiance;
  l.angular_diameter_rad = diameter_rad;
  l.color = color;
  return l;
}

SimLight point_light(const Vec3& position, double intensity) {
  SimLight l;
  l.name = "bulb";
  l.kind = SimLight::Kind::Point;
  l.position = position;
  l.intensity = intensity;
  return l;
}

SimLight sphere_light(const Vec3& position, double intensity, double radius) {
  SimLight l = point_light(position, intensity);
  l.name = "globe";
  l.kind = SimLight::Kind::Sphere;
  l.radius_m = radius;
  return l;
}

// The 10 m floor every scene stands on unless it says otherwise: z = 0, facing +z.
SimObject floor_plane(const Rgb& albedo = {0.5, 0.4, 0.3}) { return plane("floor", at({0, 0, 0}), 10, 10, albedo); }

Rgb mean_radiance(const SceneShader& shader, const Vec3& origin, const Vec3& dir, int samples, uint64_t seed = 1) {
  SampleRng rng(seed, 77);
  Rgb sum{0, 0, 0};
  for (int i = 0; i < samples; ++i) {
    const Rgb r = shader.radiance(origin, dir, rng);
    for (size_t c = 0; c < 3; ++c) sum[c] += r[c];
  }
  for (double& v : sum) v /= samples;
  return sum;
}

Rgb once(const SceneShader& shader, const Vec3& origin, const Vec3& dir) {
  SampleRng rng(1, 1);
  return shader.radiance(origin, dir, rng);
}

void expect_rgb_near(const Rgb& got, const Rgb& want, double relative, const std::string& what = "") {
  for (size_t c = 0; c < 3; ++c)
    EXPECT_NEAR(got[c], want[c], relative * std::abs(want[c]) + 1e-300) << what << " channel " << c;
}

Vec3 reflect(const Vec3& v, const Vec3& n) { return v - (2 * dot(v, n)) * n; }

Vec3 random_unit(SampleRng& rng) {
  const double z = 2 * rng.uniform() - 1, phi = 2 * kPi * rng.uniform();
  const double r = std::sqrt(1 - z * z);
  return {r * std::cos(phi), r * std::sin(phi), z};
}

TEST(SceneShader, LambertianUnderAHardDirectionalLightIsExact) {
  SimScene scene;
  const Rgb albedo{0.5, 0.4, 0.3}, color{1, 0.9, 0.8};
  const double theta = 40 * kPi / 180, E = 3;
  scene.objects = {floor_plane(albedo), sphere("ball", {2, 2, 1}, 0.2, {0.6, 0.6, 0.6})};
  scene.lights = {directional({std::sin(theta), 0, std::cos(theta)}, E, 0, color)};
  const SceneShader shader(scene, false);
  // rho E cos(theta) / pi, from any viewing direction; exact up to rounding (1e-12 relative).
  const Rgb expected{albedo[0] * color[0] * E * std::cos(theta) / kPi, albedo[1] * color[1] * E * std::cos(theta) / kPi,
                     albedo[2] * color[2] * E * std::cos(theta) / kPi};
  expect_rgb_near(once(shader, {0.1, 0.2, 1}, {0, 0, -1}), expected, 1e-12);
  expect_rgb_near(once(shader, {-0.5, 0.7, 0.4}, normalized(Vec3{0.6, -0.5, -0.4})), expected, 1e-12);
  // Two-sided: from below the floor shows its underside, which faces away from the light.
  EXPECT_EQ(once(shader, {0.1, 0.2, -1}, {0, 0, 1}), (Rgb{0, 0, 0}));
  // A sphere point with normal n: rho E max(0, n.L) / pi.
  const Vec3 L{std::sin(theta), 0, std::cos(theta)};
  for (const Vec3& n : {normalized(Vec3{0.3, -0.2, 0.9}), normalized(Vec3{-0.9, 0.1, 0.1})}) {
    const Vec3 p = Vec3{2, 2, 1} + 0.2 * n;
    const Rgb got = once(shader, p + 0.5 * n, -1.0 * n);
    const double cosine = std::max(0.0, dot(n, L));
    EXPECT_NEAR(got[0], 0.6 * E * cosine / kPi, 1e-12);
  }
  // A light from below lights the underside.
  scene.lights = {directional({0, std::sin(theta), -std::cos(theta)}, E, 0, color)};
  const SceneShader below(scene, false);
  expect_rgb_near(once(below, {0.1, 0.2, -1}, {0, 0, 1}), expected, 1e-12);
  EXPECT_EQ(once(below, {0.1, 0.2, 1}, {0, 0, -1}), (Rgb{0, 0, 0}));
}

TEST(SceneShader, PointLightFollowsTheInverseSquareLaw) {
  SimScene scene;
  scene.objects = {floor_plane({0.5, 0.5, 0.5})};
  scene.lights = {point_light({0.3, 0, 0.4}, 2)};
  const SceneShader shader(scene, false);
  // At the origin: d^2 = 0.25, cos = 0.4 / 0.5, E = I cos / d^2 = 6.4.
  EXPECT_NEAR(once(shader, {0, 0, 1}, {0, 0, -1})[0], 0.5 * 6.4 / kPi, 1e-12);
  // A point light is invisible: a ray through it sees the (black) sky.
  EXPECT_EQ(once(shader, {-1, 0, 0.4}, {1, 0, 0}), (Rgb{0, 0, 0}));
}

TEST(SceneShader, SphereLightMatchesItsAnalyticIrradiance) {
  SimScene scene;
  scene.objects = {floor_plane({0.5, 0.5, 0.5})};
  const double I = 2, r = 0.1;
  scene.lights = {sphere_light({0.3, 0, 0.4}, I, r)};
  const SceneShader shader(scene, false);
  // A sphere wholly above the horizon gives E = pi L sin^2(alpha) cos(theta) = I cos(theta) / d^2
  // (L = I / (pi r^2), sin alpha = r / d): 6.4 at the origin. Monte Carlo over the cone: the
  // per-sample cosine has sd ~0.06 around 0.8, so 20000 samples give ~5e-4 relative; 3e-3 is 5 sd.
  const Rgb mean = mean_radiance(shader, {0, 0, 1}, {0, 0, -1}, 20000);
  EXPECT_NEAR(mean[0], 0.5 * 6.4 / kPi, 3e-3 * 0.5 * 6.4 / kPi);
  // Seen directly, the sphere glows with its surface radiance I / (pi r^2).
  EXPECT_NEAR(once(shader, {0.3, 0, 1}, {0, 0, -1})[0], I / (kPi * r * r), 1e-12);
  // Further off to the side, the same law with the new distance and angle: centre at
  // d = (0.3, 0, 0.4) - (-0.5, 0.2, 0) -> d^2 = 0.84, cos = 0.4 / sqrt(0.84).
  const double d2 = 0.84, expected = 0.5 / kPi * I * (0.4 / std::sqrt(d2)) / d2;
  EXPECT_NEAR(mean_radiance(shader, {-0.5, 0.2, 1}, {0, 0, -1}, 20000)[0], expected, 3e-3 * expected);
}

TEST(SceneShader, ConstantSkyLightsAnOpenPlaneExactlyAndAWallHidesHalfOfIt) {
  SimScene scene;
  const Rgb L{0.2, 0.3, 0.4};
  scene.environment.radiance = L;
  scene.objects = {plane("floor", at({0, 0, 0}), 200, 200, {0.5, 0.5, 0.5})};
  const SceneShader open(scene, false);
  // Cosine-weighted sampling of a constant sky: every sample is exactly rho L.
  SampleRng rng(3, 3);
  for (int i = 0; i < 100; ++i) expect_rgb_near(open.radiance({0.1, 0.2, 1}, {0, 0, -1}, rng), 0.5 * L, 1e-12);
  // A sky ray that misses everything sees L itself.
  EXPECT_EQ(once(open, {0, 0, 1}, {0, 0, 1}), L);

  // A 100 m wall along x = 0 next to a point 1 mm away hides the half of the sky with x > 0:
  // half the cosine-weighted hemisphere, so the mean is rho L / 2. Bernoulli(1/2) samples:
  // 40000 give sd 0.5 / 200 = 0.0025 of rho L; 0.0125 is 5 sd.
  scene.objects.push_back(
      plane("wall", at({0, 0, 50}, {{{0, 0, 1}, {1, 0, 0}, {0, 1, 0}}}), 100, 100, {0.5, 0.5, 0.5}));
  const SceneShader walled(scene, false);
  const Rgb mean = mean_radiance(walled, {-1e-3, 0, 1}, {0, 0, -1}, 40000);
  for (size_t c = 0; c < 3; ++c) EXPECT_NEAR(mean[c], 0.5 * L[c] / 2, 0.0125 * 0.5 * L[c]);
}

TEST(SceneShader, DirectionalLightDiscIsVisibleInTheSky) {
  SimScene scene;
  scene.environment.radiance = {0.1, 0.2, 0.3};
  const Vec3 L = normalized(Vec3{0.2, 0.1, 1});
  const double E = 4, a = 5 * kPi / 180;
  scene.lights = {directional(L, E, 2 * a, {1, 0.5, 0.25})};
  const SceneShader shader(scene, false);
  // A disc that gives irradiance E on a surface facing it has radiance E / (pi sin^2 a).
  const double disc = E / (kPi * std::sin(a) * std::sin(a));
  expect_rgb_near(once(shader, {0, 0, 0}, L), {0.1 + disc, 0.2 + 0.5 * disc, 0.3 + 0.25 * disc}, 1e-12);
  // Just inside and just outside the disc's edge.
  const Frame3 f = frame_around(L);
  auto off_axis = [&](double angle) { return std::cos(angle) * L + std::sin(angle) * normalized(f.t + f.b); };
  EXPECT_NEAR(once(shader, {0, 0, 0}, off_axis(0.99 * a))[0], 0.1 + disc, 1e-12 * disc);
  EXPECT_EQ(once(shader, {0, 0, 0}, off_axis(1.01 * a)), scene.environment.radiance);
  // A light without a diameter is invisible.
  scene.lights = {directional(L, E, 0)};
  EXPECT_EQ(once(SceneShader(scene, false), {0, 0, 0}, L), scene.environment.radiance);
}

TEST(SceneShader, SkyLightDoesNotCountLightDiscsTwice) {
  // A 20-degree disc overhead plus a constant sky over an open floor: rho L from the sky and
  // rho E / pi from the light. Were the ambient ray to see the disc too, the light's share would
  // double (the disc covers sin^2(a) of the cosine-weighted hemisphere, at radiance
  // E / (pi sin^2 a)). The per-sample spread is the cosine across the disc (< 1.6 %), so 4000
  // samples pin the mean to ~1e-4; 2e-3 relative is a safe bound.
  SimScene scene;
  const double E = 3, rho = 0.5, L = 0.2;
  scene.environment.radiance = {L, L, L};
  scene.objects = {floor_plane({rho, rho, rho})};
  scene.lights = {directional({0, 0, 1}, E, 20 * kPi / 180)};
  const SceneShader shader(scene, false);
  const double expected = rho * L + rho * E / kPi;
  EXPECT_NEAR(mean_radiance(shader, {0, 0, 1}, {0, 0, -1}, 4000)[0], expected, 2e-3 * expected);
}

// Fraction of a unit disc on the far side of a chord at signed offset s (from its centre).
double disc_fraction_beyond(double s) { return (std::acos(s) - s * std::sqrt(1 - s * s)) / kPi; }

// The offset s where that fraction equals f, by bisection (the fraction falls with s).
double chord_for_fraction(double f) {
  double lo = -1, hi = 1;
  for (int i = 0; i < 100; ++i) {
    const double mid = (lo + hi) / 2;
    (disc_fraction_beyond(mid) > f ? lo : hi) = mid;
  }
  return (lo + hi) / 2;
}

TEST(SceneShader, PenumbraOfAnEdgeMatchesTheUniformDisc) {
  // A light of angular diameter 4 degrees straight overhead, an opaque sheet at h = 0.1 m covering
  // x < 0, the floor below. A floor point at x sees the part of the disc beyond the edge: in the
  // tangent plane a disc of radius R = h tan(a), cut by a chord at -x / R, so the lit fraction is
  // the uniform-disc integral F(-x / R) and the 10 %-90 % ramp is 2 * 0.687 R wide (4.8 mm).
  SimScene scene;
  const double a = 2 * kPi / 180, h = 0.1, E = 2, rho = 0.5;
  scene.objects = {floor_plane({rho, rho, rho}), plane("sheet", at({-1, 0, h}), 2, 4, {0.5, 0.5, 0.5})};
  scene.lights = {directional({0, 0, 1}, E, 2 * a)};
  const SceneShader shader(scene, false);
  const double R = h * std::tan(a), lit = rho * E / kPi;
  auto fraction_at = [&](double x) { return mean_radiance(shader, {x, 0, h / 2}, {0, 0, -1}, 20000)[0] / lit; };
  // Monte Carlo: Bernoulli sd <= 0.5 / sqrt(20000) = 0.0035; the tangent-plane picture is off by
  // ~1.5 a^2 = 2e-3 (projection) plus a^2/2 (cosine across the disc). 0.015 covers 4 sd + model.
  for (double f : {0.1, 0.5, 0.9}) {
    const double x = -chord_for_fraction(f) * R;
    EXPECT_NEAR(fraction_at(x), f, 0.015) << "at x = " << x << " (" << f * 100 << " % lit expected)";
  }
  // Outside the penumbra: full shadow is exactly 0; full light averages to E exactly (the
  // per-sample spread is only the cosine across the disc, ~6e-4, so 1e-4 is generous).
  EXPECT_EQ(fraction_at(-1.2 * R), 0.0);
  EXPECT_NEAR(fraction_at(1.2 * R), 1.0, 1e-4);
}

TEST(SceneShader, MirrorSphereNormalIsExact) {
  // A light disc only 2e-5 rad across seen in a mirror sphere: rays whose exact reflection lies
  // at 0.95 of its radius from its centre must see it, at 1.05 must not. That needs the
  // reflection (so the sphere's normal) right to 5e-7 rad; a single-precision sphere is off by
  // ~1e-5 rad here.
  SimScene scene;
  const Vec3 centre{0.1, -0.2, 0.3};
  const double radius = 0.05, a = 1e-5;
  scene.objects = {sphere("probe", centre, radius, {1, 1, 1}, true)};
  const Vec3 L = normalized(Vec3{0.3, 0.2, 1});
  scene.lights = {directional(L, 1, 2 * a)};
  const SceneShader shader(scene, false);
  const double disc = 1 / (kPi * std::sin(a) * std::sin(a));
  SampleRng rng(21, 5);
  const Frame3 f = frame_around(L);
  int tried = 0;
  while (tried < 200) {
    const Vec3 n = random_unit(rng);
    if (dot(n, L) < 0.2) continue;
    ++tried;
    const double phi = 2 * kPi * rng.uniform();
    const Vec3 side = std::cos(phi) * f.t + std::sin(phi) * f.b;
    for (double k : {0.95, 1.05}) {
      const Vec3 r = std::cos(k * a) * L + std::sin(k * a) * side;  // the wanted reflection
      const Vec3 d = reflect(r, n);                                 // the camera ray that gives it
      const Vec3 origin = centre + radius * n - 1.5 * d;
      const Rgb got = once(shader, origin, d);
      if (k < 1)
        EXPECT_NEAR(got[0], disc, 1e-9 * disc) << "normal " << n[0] << " " << n[1] << " " << n[2];
      else
        EXPECT_EQ(got[0], 0.0) << "normal " << n[0] << " " << n[1] << " " << n[2];
    }
  }
}


TEST(SceneShader, MirrorSphereReflectsTheSkyAlongTheMirrorDirection) {
  // Each of the sky's 32 pixel centres, seen in a mirror sphere along r = d - 2 (d.n) n from
  // several random normals, shows that pixel times the mirror's reflectance.
  const fs::path path = temp_dir("mirror") / "sky.hdr";
  const std::vector<Rgb> pixels = test::write_test_sky(path);
  SimScene scene;
  scene.environment.hdr_path = path;
  scene.environment.radiance = {1, 1, 1};
  const Vec3 centre{0, 0, 0.5};
  const double radius = 0.04;
  const Rgb reflectance{0.9, 0.8, 0.7};
  scene.objects = {sphere("probe", centre, radius, reflectance, true)};
  const SceneShader shader(scene, false);
  SampleRng rng(8, 8);
  for (int row = 0; row < 4; ++row)
    for (int col = 0; col < 8; ++col) {
      const double phi = 2 * kPi * (col + 0.5) / 8, theta = kPi * (row + 0.5) / 4;
      const Vec3 r{std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
      for (int k = 0; k < 4; ++k) {
        Vec3 n;
        do n = normalized(r + random_unit(rng));
        while (dot(n, r) < 0.2);
        const Vec3 d = reflect(r, n);
        const Rgb got = once(shader, centre + radius * n - 2.0 * d, d);
        const Rgb& p = pixels[size_t(row * 8 + col)];
        // Float pixels and ~1e-15 of bilinear weight from the round trip through the direction.
        expect_rgb_near(got, {reflectance[0] * p[0], reflectance[1] * p[1], reflectance[2] * p[2]}, 1e-6,
                        fmt::format("pixel {} {}", row, col));
      }
    }
}

TEST(SceneShader, MirrorShowsShadedSurfacesAndOneBounceOnly) {
  // A floor mirror reflects a grey ceiling lit by a point light between them: reflectance times
  // the ceiling's own rho I cos / (pi d^2). The reflected ray starts 10 um off the mirror, which
  // moves the ceiling point by about as much: 1e-4 relative.
  SimScene scene;
  const Rgb mirror{0.9, 0.8, 0.7};
  SimObject floor_mirror = plane("mirror", at({0, 0, 0}), 4, 4, mirror);
  floor_mirror.material.kind = SimMaterial::Kind::Mirror;
  scene.objects = {floor_mirror, plane("ceiling", at({0, 0, 1}), 4, 4, {0.5, 0.5, 0.5})};
  scene.lights = {point_light({0, 0, 0.5}, 1)};
  const SceneShader shader(scene, false);
  // Camera at (-0.2, 0, 0.5) looking at the mirror's origin: the reflection meets the ceiling at
  // (0.4, 0, 1), which sees the light at d^2 = 0.41 and cos = 0.5 / sqrt(0.41).
  const double E = 0.5 / std::sqrt(0.41) / 0.41;
  expect_rgb_near(once(shader, {-0.2, 0, 0.5}, normalized(Vec3{0.2, 0, -0.5})),
                  {mirror[0] * 0.5 * E / kPi, mirror[1] * 0.5 * E / kPi, mirror[2] * 0.5 * E / kPi}, 1e-4);

  // A sphere light seen in the mirror glows with its reflected radiance.
  SimScene globe;
  globe.objects = {floor_mirror};
  globe.lights = {sphere_light({0.3, 0, 0.5}, 1, 0.05)};
  const double glow = 1 / (kPi * 0.05 * 0.05);
  expect_rgb_near(once(SceneShader(globe, false), {-0.3, 0, 0.5}, normalized(Vec3{0.3, 0, -0.5})),
                  {mirror[0] * glow, mirror[1] * glow, mirror[2] * glow}, 1e-12);

  // Two mirrors: the second one shows the sky (and light discs) along its own reflection only.
  SimScene two;
  two.environment.radiance = {0.2, 0.2, 0.2};
  SimObject wall_mirror = plane("wall", at({1, 0, 1}, {{{0, 0, 1}, {0, 1, 0}, {-1, 0, 0}}}), 2, 2, {0.5, 0.5, 0.5});
  wall_mirror.material.kind = SimMaterial::Kind::Mirror;
  two.objects = {floor_mirror, wall_mirror};
  const Vec3 r2 = normalized(Vec3{-0.5, 0, 1});  // after the floor at (0.5, 0, 0) and the wall at (1, 0, 1)
  two.lights = {directional(r2, 3, 0.1)};
  const SceneShader shader2(two, false);
  const double disc = 3 / (kPi * std::sin(0.05) * std::sin(0.05));
  const Rgb got = once(shader2, {0, 0, 1}, normalized(Vec3{0.5, 0, -1}));
  for (size_t c = 0; c < 3; ++c) EXPECT_NEAR(got[c], mirror[c] * 0.5 * (0.2 + disc), 1e-9 * disc);
}

// tag36h11's cells, 1 = paper, from the family's bit layout (see SimTexture tests).
std::vector<int> tag36h11_cells(int id) {
  const TagFamilyPtr family = create_tag_family("tag36h11");
  std::vector<int> white(100, 0);
  for (int i = 0; i < 10; ++i)
    white[size_t(i)] = white[size_t(90 + i)] = white[size_t(i * 10)] = white[size_t(i * 10 + 9)] = 1;
  const uint64_t code = family->codes[id];
  for (uint32_t i = 0; i < family->nbits; ++i)
    if ((code >> (family->nbits - 1 - i)) & 1u) white[size_t((family->bit_y[i] + 1) * 10 + family->bit_x[i] + 1)] = 1;
  return white;
}

TEST(SceneShader, AprilTagPlaneShowsEachCellInThePlanesFrame) {
  // A 10 cm tag36h11 (10 x 10 cells of 1 cm), turned 90 degrees about z, under E = pi straight
  // down: radiance = the cell's reflectance exactly. Its local +y (the printed top) is world -x.
  SimScene scene;
  SimObject tag = plane("tag", at({0.2, 0.3, 0}, rot_z(kPi / 2)), 0.1, 0.1, {1, 1, 1});
  tag.material.texture.kind = SimTexture::Kind::AprilTag;
  tag.material.texture.family = "tag36h11";
  tag.material.texture.tag_id = 5;
  scene.objects = {tag};
  scene.lights = {directional({0, 0, 1}, kPi)};
  const SceneShader shader(scene, false);
  const std::vector<int> white = tag36h11_cells(5);
  const Mat3 R = rot_z(kPi / 2);
  for (int row = 0; row < 10; ++row)
    for (int col = 0; col < 10; ++col) {
      const Vec3 local{(col + 0.5 - 5) * 0.01, (5 - row - 0.5) * 0.01, 0};
      const Vec3 world = Vec3{0.2, 0.3, 0} + mat_mul(R, local);
      const Rgb expected = white[size_t(row * 10 + col)] ? tag.material.texture.light : tag.material.texture.dark;
      expect_rgb_near(once(shader, world + Vec3{0, 0, 0.5}, {0, 0, -1}), expected, 1e-12,
                      fmt::format("cell {} {}", row, col));
    }
}

TEST(SceneShader, ChessboardTopLeftSquareIsDark) {
  SimScene scene;
  SimObject board = plane("board", at({0, 0, 0}), 0.3, 0.2, {1, 1, 1});
  board.material.texture.kind = SimTexture::Kind::Chessboard;
  board.material.texture.rows = 2;
  board.material.texture.cols = 3;
  scene.objects = {board};
  scene.lights = {directional({0, 0, 1}, kPi)};
  const SceneShader shader(scene, false);
  const Rgb dark = board.material.texture.dark, light = board.material.texture.light;
  auto at_xy = [&](double x, double y) { return once(shader, {x, y, 1}, {0, 0, -1}); };
  expect_rgb_near(at_xy(-0.1, 0.05), dark, 1e-12);    // top-left (local -x, +y)
  expect_rgb_near(at_xy(0.0, 0.05), light, 1e-12);    // its right neighbour
  expect_rgb_near(at_xy(-0.1, -0.05), light, 1e-12);  // below it
  expect_rgb_near(at_xy(0.1, -0.05), light, 1e-12);   // bottom-right: row 1 + col 2 is odd
}

TEST(SceneShader, ContactShadowsReachTheContact) {
  // A 10 cm wall standing on the floor along x = 0, a hard light at 45 degrees from -x: the
  // floor is shadowed on 0 < x < 0.1 m. Shadow rays start 10 um above the floor (the stated
  // offset), which keeps the shadow's two edges right to within 20 um of where they belong.
  SimScene scene;
  scene.objects = {floor_plane({0.5, 0.5, 0.5}),
                   plane("wall", at({0, 0, 0.05}, {{{0, 0, 1}, {1, 0, 0}, {0, 1, 0}}}), 1, 0.1, {0.5, 0.5, 0.5})};
  scene.lights = {directional({-1, 0, 1}, 2)};
  const SceneShader shader(scene, false);
  const double lit = 0.5 * 2 * std::sqrt(0.5) / kPi;
  auto floor_at = [&](double x) { return once(shader, {x, 0.01, 0.5}, {0, 0, -1})[0]; };
  EXPECT_NEAR(floor_at(-20e-6), lit, 1e-12);
  EXPECT_EQ(floor_at(20e-6), 0.0);
  EXPECT_EQ(floor_at(0.1 - 20e-6), 0.0);
  EXPECT_NEAR(floor_at(0.1 + 20e-6), lit, 1e-12);
}

TEST(SceneShader, VirtualObjectsTakePartOnlyWhenIncluded) {
  SimScene scene;
  SimObject ball = sphere("ghost", {0, 0, 0.3}, 0.1, {0.7, 0.7, 0.7});
  ball.is_virtual = true;
  scene.objects = {floor_plane({0.5, 0.5, 0.5}), ball};
  scene.lights = {directional({0, 0, 1}, kPi)};
  EXPECT_TRUE(scene.has_virtual_objects());
  const Vec3 top{0, 0, 1}, down{0, 0, -1};
  {
    const SceneShader camera(scene, false);
    EXPECT_NEAR(once(camera, top, down)[0], 0.5, 1e-12);  // through the ghost to the lit floor
  }
  {
    const SceneShader composite(scene, true);
    EXPECT_NEAR(once(composite, top, down)[0], 0.7, 1e-12);           // the ball's top, facing the light
    EXPECT_EQ(once(composite, {0, 0, 0.1}, down)[0], 0.0);            // the floor under it, in its shadow
    EXPECT_NEAR(once(composite, {0.15, 0, 1}, down)[0], 0.5, 1e-12);  // beside the shadow
  }
}

TEST(SceneShader, ShadowlessObjectsAreSeenButCastNoShadow) {
  SimScene scene;
  SimObject ball = sphere("glass", {0, 0, 0.3}, 0.1, {0.7, 0.7, 0.7});
  ball.casts_shadows = false;
  scene.objects = {floor_plane({0.5, 0.5, 0.5}), ball};
  scene.lights = {directional({0, 0, 1}, kPi)};
  const SceneShader shader(scene, false);
  EXPECT_NEAR(once(shader, {0, 0, 1}, {0, 0, -1})[0], 0.7, 1e-12);
  EXPECT_NEAR(once(shader, {0, 0, 0.1}, {0, 0, -1})[0], 0.5, 1e-12);
}

TEST(SceneShader, GltfMeshIsPlacedScaledAndCastsShadows) {
  // tests/scene's triangle: after the node transform and glTF's y-up turn, (0,-2,0), (0.5,-2,0),
  // (0,-2,0.5) facing -y, base colour (0.2, 0.4, 0.6). Scaled by 2 and moved by (1, 3, 0.1): a
  // right triangle with legs 1 m in the plane y = -1, corner at (1, -1, 0.1).
  const fs::path path = temp_dir("mesh") / "triangle.gltf";
  std::ofstream(path) << render_test::triangle_gltf();
  SimScene scene;
  SimObject mesh;
  mesh.name = "tri";
  mesh.shape = SimObject::Shape::Mesh;
  mesh.mesh_path = path;
  mesh.mesh_scale = 2;
  mesh.T_world_object = at({1, 3, 0.1});
  mesh.material.albedo = {0.5, 0.5, 0.5};
  // A backdrop at y = 0 facing -y (x cross y = -y).
  scene.objects = {mesh,
                   plane("backdrop", at({0, 0, 0}, {{{1, 0, 0}, {0, 0, 1}, {0, -1, 0}}}), 10, 10, {0.5, 0.5, 0.5})};
  scene.lights = {directional({0, -1, 0}, 2)};
  const SceneShader shader(scene, false);
  const Rgb lit_triangle{0.5 * 0.2 * 2 / kPi, 0.5 * 0.4 * 2 / kPi, 0.5 * 0.6 * 2 / kPi};
  // Single-precision triangles: 1e-6 relative.
  expect_rgb_near(once(shader, {1.2, -3, 0.3}, {0, 1, 0}), lit_triangle, 1e-6);
  EXPECT_EQ(once(shader, {0.95, -3, 0.3}, {0, 1, 0})[0], 0.5 * 2 / kPi);            // past its edge: the backdrop
  EXPECT_EQ(once(shader, {1.2, -0.5, 0.3}, {0, 1, 0})[0], 0.0);                     // the backdrop in its shadow
  EXPECT_NEAR(once(shader, {1.8, -0.5, 0.9}, {0, 1, 0})[0], 0.5 * 2 / kPi, 1e-12);  // beside the shadow
}

std::string asset_error_of(const SimScene& scene) {
  try {
    SceneShader shader(scene, true);
  } catch (const AssetError& e) {
    return e.what();
  }
  return "no AssetError";
}

TEST(SceneShader, MissingAssetsNameTheFile) {
  const fs::path dir = temp_dir("missing");
  SimScene scene;
  scene.environment.hdr_path = dir / "no_sky.hdr";
  EXPECT_NE(asset_error_of(scene).find("no_sky.hdr"), std::string::npos);

  scene = SimScene{};
  SimObject poster = plane("poster", at({0, 0, 0}), 1, 1, {1, 1, 1});
  poster.material.texture.kind = SimTexture::Kind::Image;
  poster.material.texture.image_path = dir / "no_poster.png";
  scene.objects = {poster};
  EXPECT_NE(asset_error_of(scene).find("no_poster.png"), std::string::npos);

  scene = SimScene{};
  SimObject mesh;
  mesh.name = "statue";
  mesh.shape = SimObject::Shape::Mesh;
  mesh.mesh_path = dir / "no_statue.gltf";
  mesh.is_virtual = true;  // virtual objects are loaded for the composite
  scene.objects = {mesh};
  const std::string message = asset_error_of(scene);
  EXPECT_NE(message.find("no_statue.gltf"), std::string::npos) << message;
  EXPECT_NE(message.find("statue"), std::string::npos) << message;
}

TEST(SceneShader, BadObjectsAndLightsNameThemselves) {
  auto message = [](const SimScene& scene) {
    try {
      SceneShader shader(scene, false);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no exception");
  };
  SimScene scene;
  scene.objects = {plane("flat", at({0, 0, 0}), 0, 1, {1, 1, 1})};
  EXPECT_NE(message(scene).find("flat"), std::string::npos);
  SimObject ball = sphere("ball", {0, 0, 0}, 0.1, {1, 1, 1});
  ball.material.texture.kind = SimTexture::Kind::Chessboard;
  scene.objects = {ball};
  EXPECT_NE(message(scene).find("ball"), std::string::npos);
  scene.objects = {sphere("dot", {0, 0, 0}, -1, {1, 1, 1})};
  EXPECT_NE(message(scene).find("dot"), std::string::npos);
  scene.objects.clear();
  scene.lights = {sphere_light({0, 0, 1}, 1, 0)};
  EXPECT_NE(message(scene).find("globe"), std::string::npos);
  scene.lights = {directional({0, 0, 1}, -1)};
  EXPECT_NE(message(scene).find("sun"), std::string::npos);
}

TEST(SceneShader, SameSeedsGiveBitIdenticalRadiance) {
  SimScene scene;
  scene.environment.radiance = {0.1, 0.12, 0.15};
  scene.objects = {floor_plane(), sphere("probe", {0, 0, 0.05}, 0.05, {0.9, 0.9, 0.9}, true),
                   sphere("ball", {0.2, 0, 0.05}, 0.05, {0.6, 0.5, 0.4})};
  scene.lights = {directional({0.3, 0.2, 1}, 3, 0.01), sphere_light({-0.3, 0.2, 0.5}, 1, 0.05)};
  const SceneShader a(scene, false), b(scene, false);
  std::vector<Vec3> dirs;
  SampleRng pick(4, 4);
  for (int i = 0; i < 500; ++i)
    dirs.push_back(normalized(Vec3{0, 0, 0.05} + 0.15 * random_unit(pick) - Vec3{0, -0.4, 0.3}));
  const Vec3 eye{0, -0.4, 0.3};
  auto render = [&](const SceneShader& shader, size_t begin, size_t step, std::vector<Rgb>& out) {
    for (size_t i = begin; i < dirs.size(); i += step) {
      SampleRng rng(99, i);
      out[i] = shader.radiance(eye, dirs[i], rng);
    }
  };
  std::vector<Rgb> first(dirs.size()), second(dirs.size()), threaded(dirs.size());
  render(a, 0, 1, first);
  render(b, 0, 1, second);
  std::thread t1([&] { render(a, 0, 2, threaded); }), t2([&] { render(a, 1, 2, threaded); });
  t1.join();
  t2.join();
  EXPECT_EQ(first, second);
  EXPECT_EQ(first, threaded);
  // And the random numbers matter: another seed gives other soft-shadow samples somewhere.
  bool any_difference = false;
  for (size_t i = 0; i < dirs.size(); ++i) {
    SampleRng rng(100, i);
    any_difference |= a.radiance(eye, dirs[i], rng) != first[i];
  }
  EXPECT_TRUE(any_difference);
}

// A builtin cube (6 cm, base on z = 0, centred) on the floor: rays straight down hit its top
// inside |x| < 3 cm and the floor outside, both lit exactly by the overhead light.
TEST(SceneShader, BuiltinCubeStandsOnItsBase) {
  SimScene scene;
  scene.objects.push_back(floor_plane({0.5, 0.5, 0.5}));
  SimObject cube;
  cube.name = "cube";
  cube.shape = SimObject::Shape::Mesh;
  cube.mesh_builtin = "builtin:cube";
  cube.material.albedo = {0.8, 0.3, 0.1};
  scene.objects.push_back(cube);
  scene.lights.push_back(directional({0, 0, 1}, 2.0));
  const SceneShader shader(scene, false);
  const Vec3 down{0, 0, -1};
  expect_rgb_near(once(shader, {0.025, 0.01, 1}, down), {0.8 * 2 / kPi, 0.3 * 2 / kPi, 0.1 * 2 / kPi}, 1e-6, "top");
  expect_rgb_near(once(shader, {0.035, 0.01, 1}, down), {0.5 * 2 / kPi, 0.5 * 2 / kPi, 0.5 * 2 / kPi}, 1e-6, "floor");
  // Its +x side seen horizontally, lit at 45 degrees: just below the 6 cm top the face is there,
  // just above it the ray misses everything (no sky: black).
  scene.lights = {directional(normalized(Vec3{1, 0, 1}), 2.0)};
  const SceneShader side_lit(scene, false);
  const double side = 0.8 * 2 * std::cos(kPi / 4) / kPi;
  expect_rgb_near(once(side_lit, {1, 0, 0.059}, {-1, 0, 0}), {side, side * 0.3 / 0.8, side * 0.1 / 0.8}, 1e-6, "side");
  EXPECT_EQ(once(side_lit, {1, 0, 0.061}, {-1, 0, 0}), (Rgb{0, 0, 0}));
}

}  // namespace
}  // namespace arpipe::sim
