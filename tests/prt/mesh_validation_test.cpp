// A malformed mesh is refused with an AssetError that says what is wrong, before any ray is cast;
// bad settings are std::invalid_argument.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "core/scene/asset_error.h"
#include "core/scene/builtin_meshes.h"
#include "render/prt/prt_bake.h"

namespace arpipe {
namespace {

std::string bake_error(const Mesh& mesh) {
  try {
    bake_prt(mesh, PrtBakeSettings{});
  } catch (const AssetError& e) {
    return e.what();
  }
  return "";
}

TEST(PrtMeshValidation, RefusesMalformedMeshes) {
  const Mesh good = make_cube_mesh(0.06, 1);
  {
    Mesh m = good;
    m.normals.resize(m.normals.size() - 3);
    EXPECT_NE(bake_error(m).find("normals"), std::string::npos) << bake_error(m);
  }
  {
    Mesh m = good;
    m.positions[4] = std::numeric_limits<float>::quiet_NaN();
    EXPECT_NE(bake_error(m).find("vertex 1 has a non-finite position"), std::string::npos) << bake_error(m);
  }
  {
    Mesh m = good;
    m.normals[0] = std::numeric_limits<float>::infinity();
    EXPECT_NE(bake_error(m).find("vertex 0 has a non-finite normal"), std::string::npos) << bake_error(m);
  }
  {
    Mesh m = good;
    m.normals[3] = m.normals[4] = m.normals[5] = 0;
    EXPECT_NE(bake_error(m).find("vertex 1 has a zero-length normal"), std::string::npos) << bake_error(m);
  }
  {
    Mesh m = good;
    m.indices[5] = uint32_t(m.vertex_count());
    EXPECT_NE(bake_error(m).find("index 5 (triangle 1)"), std::string::npos) << bake_error(m);
    EXPECT_NE(bake_error(m).find("out of range"), std::string::npos) << bake_error(m);
  }
  {
    Mesh m = good;
    m.indices.pop_back();
    EXPECT_NE(bake_error(m).find("multiple of 3"), std::string::npos) << bake_error(m);
  }
  {
    Mesh m = good;
    m.parts[0].index_count += 3;
    EXPECT_NE(bake_error(m).find("part 0"), std::string::npos) << bake_error(m);
  }
  EXPECT_EQ(bake_error(good), "");
}

TEST(PrtMeshValidation, RefusesBadSettings) {
  const Mesh cube = make_cube_mesh(0.06, 1);
  PrtBakeSettings s;
  s.bands = 0;
  EXPECT_THROW(bake_prt(cube, s), std::invalid_argument);
  s = {};
  s.samples_per_axis = 0;
  EXPECT_THROW(bake_prt(cube, s), std::invalid_argument);
  s = {};
  s.ray_offset = -1;
  EXPECT_THROW(bake_prt(cube, s), std::invalid_argument);
}

TEST(PrtTransferKind, NamesRoundTrip) {
  for (TransferKind k : {TransferKind::Unshadowed, TransferKind::Shadowed, TransferKind::Interreflected})
    EXPECT_EQ(parse_transfer_kind(transfer_kind_name(k)), k);
  EXPECT_FALSE(parse_transfer_kind("Shadowed"));
  EXPECT_FALSE(parse_transfer_kind(""));
}

}  // namespace
}  // namespace arpipe
