#include "core/probe/mirror_probe.h"
#include "core/geometry/math_constants.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "core/probe/brightest_components.h"
#include "core/sh/sh_basis.h"

namespace arpipe {

namespace {


struct Sample {
  Vec3 dir;      // reflected direction, world
  Vec3 normal;   // where on the ball it was reflected
  Vec3 rgb;      // radiance / reflectance
  double lum = 0;
  double omega = 0;  // solid angle of reflected directions the pixel covers
  int cell = 0;
  bool clipped = false;
  int light = -1;
};

}  // namespace

Vec3 EnvironmentMap::direction(int i, int j) const {
  const double phi = 2 * kPi * (i + 0.5) / width, theta = kPi * (j + 0.5) / height;
  return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}

double EnvironmentMap::cell_solid_angle(int j) const {
  return (2 * kPi / width) * (std::cos(kPi * j / height) - std::cos(kPi * (j + 1) / height));
}

int EnvironmentMap::cell_of(const Vec3& d) const {
  double phi = std::atan2(d[1], d[0]);
  if (phi < 0) phi += 2 * kPi;
  const double theta = std::acos(std::clamp(d[2], -1.0, 1.0));
  const int i = std::clamp(int(phi / (2 * kPi) * width), 0, width - 1);
  const int j = std::clamp(int(theta / kPi * height), 0, height - 1);
  return j * width + i;
}

MirrorProbeResult analyse_mirror_probe(const ProbeSphere& sphere, const ProbeRegion& region, const LinearPatch& patch,
                                       const MirrorProbeOptions& options) {
  MirrorProbeResult res;
  EnvironmentMap& map = res.map;
  map.width = std::max(8, options.map_width);
  map.height = std::max(4, options.map_height);
  const size_t cells = size_t(map.width) * size_t(map.height);
  map.radiance.assign(cells, {0, 0, 0});
  map.weight.assign(cells, 0);
  map.seen.assign(cells, 0);
  map.light.assign(cells, 0);

  // 1. Every pixel is a sample of the environment along its reflected true view ray. The solid
  // angle of reflected directions of a pixel is 4 t^2 dOmega_pixel / r^2 (dA = t^2 dOmega / cos i
  // on the ball, dOmega_normal = dA / r^2, reflection multiplies by 4 cos i).
  const double inv_reflectance = sphere.reflectance > 0 ? 1.0 / sphere.reflectance : 1.0;
  const double r2 = sphere.radius_m * sphere.radius_m;
  thread_local std::vector<Sample> samples;
  samples.clear();
  int clipped = 0;
  for (const ProbeHit& h : region.hits) {
    if (!patch.rect.contains(h.x, h.y)) continue;
    const float* p = patch.at(h.x, h.y);
    Sample s;
    s.dir = reflect(h.view_world, h.normal_world);
    s.normal = h.normal_world;
    s.rgb = {p[0] * inv_reflectance, p[1] * inv_reflectance, p[2] * inv_reflectance};
    s.lum = rec709_luminance(s.rgb[0], s.rgb[1], s.rgb[2]);
    s.omega = 4 * h.distance_m * h.distance_m * h.pixel_solid_angle / r2;
    s.cell = map.cell_of(s.dir);
    s.clipped = patch.clipped_at(h.x, h.y);
    clipped += s.clipped ? 1 : 0;
    map.radiance[size_t(s.cell)] = map.radiance[size_t(s.cell)] + s.omega * s.rgb;
    map.weight[size_t(s.cell)] += s.omega;
    samples.push_back(s);
  }
  res.pixels = int(samples.size());
  if (samples.empty()) return res;
  res.clipped_fraction = double(clipped) / double(samples.size());

  // 2. Cell means; gaps between samples filled from their neighbours (two passes), the blind cone
  // behind the ball (and whatever else is left) by the mean radiance of everything seen.
  Vec3 seen_sum{0, 0, 0};
  double seen_w = 0, seen_omega = 0, total_omega = 0;
  for (size_t c = 0; c < cells; ++c) {
    total_omega += map.cell_solid_angle(int(c) / map.width);
    if (map.weight[c] <= 0) continue;
    seen_sum = seen_sum + map.radiance[c];
    seen_w += map.weight[c];
    map.radiance[c] = (1.0 / map.weight[c]) * map.radiance[c];
    map.seen[c] = 1;
    seen_omega += map.cell_solid_angle(int(c) / map.width);
  }
  res.seen_fraction = seen_omega / total_omega;
  const Vec3 seen_mean = (1.0 / seen_w) * seen_sum;
  std::vector<uint8_t> known(map.seen);
  for (int pass = 0; pass < 2; ++pass) {
    std::vector<uint8_t> next(known);
    for (int j = 0; j < map.height; ++j)
      for (int i = 0; i < map.width; ++i) {
        const size_t c = size_t(j) * size_t(map.width) + size_t(i);
        if (known[c]) continue;
        Vec3 sum{0, 0, 0};
        int n = 0;
        for (int dj = -1; dj <= 1; ++dj)
          for (int di = -1; di <= 1; ++di) {
            const int jj = j + dj;
            if (jj < 0 || jj >= map.height) continue;
            const size_t cc = size_t(jj) * size_t(map.width) + size_t((i + di + map.width) % map.width);
            if (!known[cc]) continue;
            sum = sum + map.radiance[cc];
            ++n;
          }
        if (n >= 2) {
          map.radiance[c] = (1.0 / n) * sum;
          next[c] = 1;
        }
      }
    known.swap(next);
  }
  for (size_t c = 0; c < cells; ++c)
    if (!known[c]) map.radiance[c] = seen_mean;

  // 3. Lights: the brightest unassigned pixel, if it stands out of the map's median by
  // min_peak_contrast, grows (4-connected in the image) over pixels above light_threshold of its
  // peak, plus one ring of mixed edge pixels; the background (the median) is taken off each pixel.
  std::vector<double> lums;
  for (size_t c = 0; c < cells; ++c)
    if (map.seen[c]) lums.push_back(rec709_luminance(map.radiance[c][0], map.radiance[c][1], map.radiance[c][2]));
  std::nth_element(lums.begin(), lums.begin() + long(lums.size() / 2), lums.end());
  const double median = lums[lums.size() / 2];
  // The background under a light: the median's luminance in the seen mean's colour.
  const Vec3 background = (median > 0 ? median / std::max(1e-12, rec709_luminance(seen_mean[0], seen_mean[1], seen_mean[2]))
                                      : 0.0) * seen_mean;
  std::vector<int> sample_at(size_t(region.rect.width) * size_t(region.rect.height), -1);
  {
    size_t k = 0;
    for (const ProbeHit& h : region.hits) {
      if (!patch.rect.contains(h.x, h.y)) continue;
      sample_at[size_t(h.y - region.rect.y0) * size_t(region.rect.width) + size_t(h.x - region.rect.x0)] = int(k++);
    }
  }
  std::vector<std::array<int, 2>> pixel_of(samples.size());
  for (int y = 0; y < region.rect.height; ++y)
    for (int x = 0; x < region.rect.width; ++x) {
      const int k = sample_at[size_t(y) * size_t(region.rect.width) + size_t(x)];
      if (k >= 0) pixel_of[size_t(k)] = {x, y};
    }
  std::vector<int> stack, members;
  for (int li = 0; li < options.max_lights; ++li) {
    int peak = -1;
    for (size_t k = 0; k < samples.size(); ++k)
      if (samples[k].light < 0 && (peak < 0 || samples[k].lum > samples[size_t(peak)].lum)) peak = int(k);
    if (peak < 0) break;
    const double peak_lum = samples[size_t(peak)].lum;
    if (!(peak_lum >= options.min_peak_contrast * median) || !(peak_lum > 0)) break;
    const double threshold = std::max(options.light_threshold * peak_lum, 0.5 * options.min_peak_contrast * median);
    members.clear();
    stack.assign(1, peak);
    samples[size_t(peak)].light = li;
    auto at = [&](int x, int y) {
      if (x < 0 || y < 0 || x >= region.rect.width || y >= region.rect.height) return -1;
      return sample_at[size_t(y) * size_t(region.rect.width) + size_t(x)];
    };
    while (!stack.empty()) {
      const int k = stack.back();
      stack.pop_back();
      members.push_back(k);
      const auto [x, y] = pixel_of[size_t(k)];
      const int nb[4][2] = {{x - 1, y}, {x + 1, y}, {x, y - 1}, {x, y + 1}};
      for (const auto& q : nb) {
        const int kk = at(q[0], q[1]);
        if (kk < 0 || samples[size_t(kk)].light >= 0 || !(samples[size_t(kk)].lum >= threshold)) continue;
        samples[size_t(kk)].light = li;
        stack.push_back(kk);
      }
    }
    const size_t core = members.size();
    for (size_t m = 0; m < core; ++m) {
      const auto [x, y] = pixel_of[size_t(members[m])];
      const int nb[4][2] = {{x - 1, y}, {x + 1, y}, {x, y - 1}, {x, y + 1}};
      for (const auto& q : nb) {
        const int kk = at(q[0], q[1]);
        if (kk < 0 || samples[size_t(kk)].light >= 0) continue;
        samples[size_t(kk)].light = li;
        members.push_back(kk);
      }
    }
    MirrorLight ml;
    Vec3 dir_sum{0, 0, 0}, normal_sum{0, 0, 0}, irradiance{0, 0, 0};
    double omega = 0;
    int clipped_px = 0;
    for (size_t m = 0; m < members.size(); ++m) {
      const Sample& s = samples[size_t(members[m])];
      const Vec3 excess{std::max(0.0, s.rgb[0] - background[0]), std::max(0.0, s.rgb[1] - background[1]),
                        std::max(0.0, s.rgb[2] - background[2])};
      irradiance = irradiance + s.omega * excess;
      // The direction from the core only: the edge ring is half background and noisier.
      if (m < core) {
        const double w = s.omega * rec709_luminance(excess[0], excess[1], excess[2]);
        dir_sum = dir_sum + w * s.dir;
        normal_sum = normal_sum + w * s.normal;
        omega += s.omega;
      }
      clipped_px += s.clipped ? 1 : 0;
      map.light[size_t(s.cell)] = uint8_t(li + 1);
    }
    if (!(norm(dir_sum) > 0)) break;
    ml.light.direction_world = normalized(dir_sum);
    ml.reflection_point_world = sphere.center_world + sphere.radius_m * normalized(normal_sum);
    ml.direction_from_point = ml.light.direction_world;
    if (options.light_distance_m > sphere.radius_m) {
      // Parallax: the ball sees the light from the reflecting point p; the light at distance D
      // from the centre lies at p + t v with |p - c + t v| = D.
      const Vec3 pc = ml.reflection_point_world - sphere.center_world;
      const Vec3& v = ml.direction_from_point;
      const double b = dot(pc, v);
      const double t = -b + std::sqrt(std::max(0.0, b * b - dot(pc, pc) + options.light_distance_m * options.light_distance_m));
      ml.light.direction_world = normalized(pc + t * v);
    }
    ml.light.irradiance = irradiance;
    ml.light.angular_diameter_rad = 2 * std::sqrt(omega / kPi);
    ml.pixels = int(members.size());
    ml.clipped_fraction = double(clipped_px) / double(members.size());
    ml.clipped = clipped_px > 0;
    ml.peak_contrast = median > 0 ? peak_lum / median : 0;
    res.lights.push_back(ml);
  }

  // 4. Ambient: each light's cells replaced by the mean of the ring of non-light cells around
  // them, then the whole map projected onto SH.
  std::vector<Vec3> ambient(map.radiance);
  for (int li = 1; li <= int(res.lights.size()); ++li) {
    Vec3 ring{0, 0, 0};
    int n = 0;
    for (int j = 0; j < map.height; ++j)
      for (int i = 0; i < map.width; ++i) {
        const size_t c = size_t(j) * size_t(map.width) + size_t(i);
        if (map.light[c] != 0) continue;
        bool touches = false;
        for (int dj = -1; dj <= 1 && !touches; ++dj)
          for (int di = -1; di <= 1; ++di) {
            const int jj = j + dj;
            if (jj < 0 || jj >= map.height) continue;
            if (map.light[size_t(jj) * size_t(map.width) + size_t((i + di + map.width) % map.width)] == li) {
              touches = true;
              break;
            }
          }
        if (touches) {
          ring = ring + map.radiance[c];
          ++n;
        }
      }
    const Vec3 fill = n > 0 ? (1.0 / n) * ring : background;
    for (size_t c = 0; c < cells; ++c)
      if (map.light[c] == li) ambient[c] = fill;
  }
  res.ambient_sh = {};
  for (int j = 0; j < map.height; ++j) {
    const double omega = map.cell_solid_angle(j);
    for (int i = 0; i < map.width; ++i)
      sh_add_sample(res.ambient_sh, map.direction(i, j), ambient[size_t(j) * size_t(map.width) + size_t(i)], omega);
  }
  return res;
}

}  // namespace arpipe
