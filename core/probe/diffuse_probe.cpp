#include "core/probe/diffuse_probe.h"
#include "core/geometry/math_constants.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <vector>

#include "core/probe/brightest_components.h"
#include "core/sh/sh_basis.h"
#include "core/sh/sh_irradiance.h"

namespace arpipe {

namespace {

constexpr int kP = 5;  // E, a0, ax, ay, az
using Vec5 = std::array<double, kP>;

struct Px {
  Vec3 n;
  Vec3 y;  // radiance * pi / albedo: irradiance per channel
  double lum = 0;
};

// Solves the symmetric system A x = b (Gaussian elimination, partial pivoting); false if singular.
bool solve5(std::array<std::array<double, kP>, kP> a, Vec5 b, Vec5& x) {
  for (int c = 0; c < kP; ++c) {
    int p = c;
    for (int r = c + 1; r < kP; ++r)
      if (std::abs(a[size_t(r)][size_t(c)]) > std::abs(a[size_t(p)][size_t(c)])) p = r;
    if (!(std::abs(a[size_t(p)][size_t(c)]) > 1e-12 * (1 + std::abs(a[0][0])))) return false;
    std::swap(a[size_t(p)], a[size_t(c)]);
    std::swap(b[size_t(p)], b[size_t(c)]);
    for (int r = c + 1; r < kP; ++r) {
      const double f = a[size_t(r)][size_t(c)] / a[size_t(c)][size_t(c)];
      for (int k = c; k < kP; ++k) a[size_t(r)][size_t(k)] -= f * a[size_t(c)][size_t(k)];
      b[size_t(r)] -= f * b[size_t(c)];
    }
  }
  for (int c = kP - 1; c >= 0; --c) {
    double s = b[size_t(c)];
    for (int k = c + 1; k < kP; ++k) s -= a[size_t(c)][size_t(k)] * x[size_t(k)];
    x[size_t(c)] = s / a[size_t(c)][size_t(c)];
  }
  return true;
}

// The light at distance D = r / s from the centre (s = 0: infinitely far) lights the surface point
// p = c + r n with (n.(L - p)) / |L - p|^3 = (n.l - s) / (D^2 (1 - 2 s n.l + s^2)^(3/2)): the
// terminator moves towards the light and the near side gets brighter. E is the irradiance at the
// centre, I / D^2.
double shading(const Vec3& n, const Vec3& l, double s) {
  const double c = dot(n, l);
  if (c <= s) return 0;
  if (s == 0) return c;
  const double q = 1 - 2 * s * c + s * s;
  return (c - s) / (q * std::sqrt(q));
}


// The [1, n] block of the normal equations does not depend on the light: computed once per subset.
struct ConstantBlock {
  size_t stride = 1;
  std::array<std::array<double, 4>, 4> a{};
  std::array<std::array<double, 4>, 4> b{};  // [channel 0..2, luminance][row]
};

ConstantBlock constant_block(const std::vector<Px>& px, size_t stride) {
  ConstantBlock cb;
  cb.stride = stride;
  for (size_t i = 0; i < px.size(); i += stride) {
    const double f[4] = {1, px[i].n[0], px[i].n[1], px[i].n[2]};
    const double y[4] = {px[i].y[0], px[i].y[1], px[i].y[2], px[i].lum};
    for (size_t r = 0; r < 4; ++r) {
      for (size_t c = 0; c < 4; ++c) cb.a[r][c] += f[r] * f[c];
      for (size_t ch = 0; ch < 4; ++ch) cb.b[ch][r] += f[r] * y[ch];
    }
  }
  return cb;
}

// For a fixed direction and near-field parameter the model is linear: least squares for channel
// `ch` (3 = luminance); residuals written to `residuals` when given.
bool linear_fit(const std::vector<Px>& px, const ConstantBlock& cb, const Vec3& l, double s_near, int ch, Vec5& beta,
                double& sse, std::vector<double>* residuals = nullptr) {
  thread_local std::vector<double> f0;
  f0.clear();
  double a00 = 0, a0[4] = {0, 0, 0, 0}, b0 = 0;
  for (size_t i = 0; i < px.size(); i += cb.stride) {
    const double f = shading(px[i].n, l, s_near);
    f0.push_back(f);
    if (f == 0) continue;
    a00 += f * f;
    a0[0] += f;
    a0[1] += f * px[i].n[0];
    a0[2] += f * px[i].n[1];
    a0[3] += f * px[i].n[2];
    b0 += f * (ch == 3 ? px[i].lum : px[i].y[size_t(ch)]);
  }
  std::array<std::array<double, kP>, kP> a{};
  Vec5 b{};
  a[0][0] = a00;
  b[0] = b0;
  for (size_t r = 0; r < 4; ++r) {
    a[0][r + 1] = a[r + 1][0] = a0[r];
    b[r + 1] = cb.b[size_t(ch)][r];
    for (size_t c = 0; c < 4; ++c) a[r + 1][c + 1] = cb.a[r][c];
  }
  if (!solve5(a, b, beta)) return false;
  sse = 0;
  if (residuals) residuals->clear();
  size_t k = 0;
  for (size_t i = 0; i < px.size(); i += cb.stride, ++k) {
    const Vec3& n = px[i].n;
    const double m = beta[0] * f0[k] + beta[1] + beta[2] * n[0] + beta[3] * n[1] + beta[4] * n[2];
    const double e = (ch == 3 ? px[i].lum : px[i].y[size_t(ch)]) - m;
    sse += e * e;
    if (residuals) residuals->push_back(e);
  }
  return true;
}

void tangent_basis(const Vec3& l, Vec3& e1, Vec3& e2) {
  const Vec3 a = std::abs(l[0]) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
  e1 = normalized(cross(l, a));
  e2 = cross(l, e1);
}

}  // namespace

DiffuseFitResult fit_diffuse_probe(const ProbeSphere& sphere, const ProbeRegion& region, const LinearPatch& patch,
                                   const DiffuseFitOptions& options) {
  DiffuseFitResult res;
  const double to_irradiance = kPi / std::max(1e-6, sphere.reflectance);
  thread_local std::vector<Px> px;
  px.clear();
  int clipped = 0, total = 0;
  for (const ProbeHit& h : region.hits) {
    if (!patch.rect.contains(h.x, h.y)) continue;
    ++total;
    if (patch.clipped_at(h.x, h.y)) {  // a lower bound only: left out
      ++clipped;
      continue;
    }
    const float* p = patch.at(h.x, h.y);
    Px q;
    q.n = h.normal_world;
    q.y = {p[0] * to_irradiance, p[1] * to_irradiance, p[2] * to_irradiance};
    q.lum = rec709_luminance(q.y[0], q.y[1], q.y[2]);
    px.push_back(q);
  }
  res.clipped_fraction = total > 0 ? double(clipped) / total : 0;
  res.pixels = int(px.size());
  if (px.size() < 50) return res;

  // Initial direction: the unclamped linear fit lum ~ c0 + c.n over the brighter half (lit side).
  std::vector<double> lums;
  for (const Px& q : px) lums.push_back(q.lum);
  std::nth_element(lums.begin(), lums.begin() + long(lums.size() / 2), lums.end());
  const double median = lums[lums.size() / 2];
  Vec3 l{0, 0, 1};
  {
    std::array<std::array<double, 4>, 4> a{};
    std::array<double, 4> b{};
    for (const Px& q : px) {
      if (q.lum < median) continue;
      const double f[4] = {1, q.n[0], q.n[1], q.n[2]};
      for (int r = 0; r < 4; ++r) {
        b[size_t(r)] += f[r] * q.lum;
        for (int c = 0; c < 4; ++c) a[size_t(r)][size_t(c)] += f[r] * f[c];
      }
    }
    // Solve the 4x4 through the 5x5 solver with a dummy unit row.
    std::array<std::array<double, kP>, kP> a5{};
    Vec5 b5{}, x5{};
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 4; ++c) a5[size_t(r)][size_t(c)] = a[size_t(r)][size_t(c)];
      b5[size_t(r)] = b[size_t(r)];
    }
    a5[4][4] = 1;
    if (solve5(a5, b5, x5) && norm(Vec3{x5[1], x5[2], x5[3]}) > 0) l = normalized(Vec3{x5[1], x5[2], x5[3]});
  }

  // Variable projection: Levenberg-Marquardt on the direction (2 tangent parameters) and the
  // near-field parameter s = r / D, the linear parameters solved exactly for each trial; luminance.
  const size_t max_px = size_t(std::max(50, options.max_fit_pixels));
  const ConstantBlock sub = constant_block(px, (px.size() + max_px - 1) / max_px);
  const ConstantBlock all = sub.stride == 1 ? sub : constant_block(px, 1);
  const bool fit_s = options.light_distance_m <= 0 && options.fit_distance;
  double s_near = options.light_distance_m > 0 ? std::min(0.5, sphere.radius_m / options.light_distance_m) : 0;
  const int np = fit_s ? 3 : 2;
  Vec5 beta{};
  double sse = 0;
  if (!linear_fit(px, sub, l, s_near, 3, beta, sse)) return res;
  double lambda = 1e-3;
  const double h = 1e-5;
  std::array<std::vector<double>, 4> rv;
  auto residuals = [&](const Vec3& dir, double sn, std::vector<double>& out) {
    Vec5 bt{};
    double e = 0;
    return linear_fit(px, sub, dir, sn, 3, bt, e, &out);
  };
  auto moved = [](const Vec3& dir, const Vec3& e1, const Vec3& e2, const double* d) {
    return normalized(dir + d[0] * e1 + d[1] * e2);
  };
  int it = 0;
  bool converged = false;
  for (; it < options.max_iterations && !converged; ++it) {
    Vec3 e1, e2;
    tangent_basis(l, e1, e2);
    bool ok = residuals(l, s_near, rv[0]);
    for (int k = 0; k < np && ok; ++k) {
      double d[3] = {0, 0, 0};
      d[k] = h;
      ok = residuals(moved(l, e1, e2, d), s_near + d[2], rv[size_t(k + 1)]);
    }
    if (!ok) break;
    double jtj[3][3] = {}, g[3] = {};
    for (size_t i = 0; i < rv[0].size(); ++i) {
      double jr[3] = {0, 0, 0};
      for (int k = 0; k < np; ++k) jr[k] = (rv[size_t(k + 1)][i] - rv[0][i]) / h;
      for (int a = 0; a < np; ++a) {
        g[a] += jr[a] * rv[0][i];
        for (int b = 0; b < np; ++b) jtj[a][b] += jr[a] * jr[b];
      }
    }
    bool improved = false;
    for (int tries = 0; tries < 8 && !improved; ++tries) {
      std::array<std::array<double, kP>, kP> m{};
      Vec5 rhs{}, d5{};
      for (int a = 0; a < kP; ++a) m[size_t(a)][size_t(a)] = 1;
      for (int a = 0; a < np; ++a) {
        for (int b = 0; b < np; ++b) m[size_t(a)][size_t(b)] = jtj[a][b];
        m[size_t(a)][size_t(a)] = jtj[a][a] * (1 + lambda) + 1e-12;
        rhs[size_t(a)] = -g[a];
      }
      if (!solve5(m, rhs, d5)) break;
      const double d[3] = {d5[0], d5[1], np > 2 ? d5[2] : 0};
      const Vec3 trial = moved(l, e1, e2, d);
      const double trial_s = std::clamp(s_near + d[2], 0.0, 0.5);
      Vec5 bt{};
      double e = 0;
      if (linear_fit(px, sub, trial, trial_s, 3, bt, e) && e < sse) {
        const double step = std::hypot(d[0], d[1], d[2]);
        l = trial;
        s_near = trial_s;
        sse = e;
        lambda = std::max(1e-7, lambda * 0.3);
        improved = true;
        converged = step < 1e-6;  // 0.00006 degrees
      } else {
        lambda *= 10;
      }
    }
    if (!improved) break;
  }
  res.iterations = it;
  res.light_distance_m = s_near > 0 ? sphere.radius_m / s_near : 0;

  // Final per-channel linear fits with every pixel.
  Vec3 e{0, 0, 0}, a0{0, 0, 0};
  std::array<Vec3, 3> a{};
  for (int ch = 0; ch < 3; ++ch) {
    Vec5 bt{};
    double s = 0;
    if (!linear_fit(px, all, l, s_near, ch, bt, s)) return res;
    e[size_t(ch)] = bt[0];
    a0[size_t(ch)] = bt[1];
    for (int k = 0; k < 3; ++k) a[size_t(k)][size_t(ch)] = bt[size_t(2 + k)];
  }
  Vec5 bl{};
  double sl = 0;
  linear_fit(px, all, l, s_near, 3, bl, sl);
  double mean = 0;
  int lit = 0;
  for (const Px& q : px) {
    mean += q.lum;
    lit += dot(q.n, l) > s_near ? 1 : 0;
  }
  mean /= double(px.size());
  res.rms_residual = mean > 0 ? std::sqrt(sl / double(px.size())) / mean : 1;
  res.lit_fraction = double(lit) / double(px.size());
  if (!(rec709_luminance(e[0], e[1], e[2]) > 0)) return res;  // no light on the probe
  res.light.direction_world = l;
  res.light.irradiance = e;
  res.light.angular_diameter_rad = 0;
  res.ambient_constant = a0;
  // Irradiance a0 + a.n = A_0 L_0 Y_0 + A_1 sum L_1m Y_1m(n): Y_0 = y0 and Y_1{-1,0,1} = y1 {y, z, x},
  // y0 and y1 the basis at the pole.
  std::array<double, 4> pole;
  sh_basis(2, {0, 0, 1}, pole);
  const double y0 = pole[size_t(sh_index(0, 0))], y1 = pole[size_t(sh_index(1, 0))];
  const double per_a0 = 1.0 / (sh_cosine_lobe_constant(0) * y0), per_a1 = 1.0 / (sh_cosine_lobe_constant(1) * y1);
  res.ambient_sh = {};
  res.ambient_sh[0] = per_a0 * a0;
  res.ambient_sh[1] = per_a1 * a[1];
  res.ambient_sh[2] = per_a1 * a[2];
  res.ambient_sh[3] = per_a1 * a[0];
  res.ok = true;
  return res;
}

}  // namespace arpipe
