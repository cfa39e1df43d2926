// Per-texel SH projection of a light probe (see environment_sh.h).
#include "core/environment/environment_sh.h"

namespace arpipe {

ShRgb project_environment(const HdrEnvironment& environment, int bands) {
  ShRgb sh(bands);
  std::vector<double> basis(size_t(sh_count(bands)));
  environment.for_each_texel([&](const Vec3& direction, const Vec3& radiance, double solid_angle) {
    sh_basis(bands, direction, basis);
    for (size_t i = 0; i < basis.size(); ++i) sh.c[i] = sh.c[i] + (basis[i] * solid_angle) * radiance;
  });
  return sh;
}

}  // namespace arpipe
