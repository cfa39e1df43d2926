// Declared limits on what a physics world accepts (docs/DESIGN.md "Errors": every input is hostile
// until checked). A spec beyond them is a PhysicsError, never an allocation or a hang.
#pragma once

#include <cstddef>
#include <cstdint>

namespace arpipe::physics_limits {

inline constexpr size_t kMaxBodies = 1024;                   // rigid bodies in one world
inline constexpr size_t kMaxColliders = 4096;                // static colliders in one world
inline constexpr size_t kMaxTrianglesPerMesh = 1'000'000;    // per mesh shape (seed 003: 561k before decimation)
inline constexpr size_t kMaxTrianglesTotal = 2'000'000;      // over all mesh shapes of one world
inline constexpr size_t kMaxVerticesPerMesh = 3'000'000;
inline constexpr size_t kMaxTrackKeys = 1'000'000;           // poses on one kinematic track
inline constexpr double kMaxSizeM = 10'000;                  // any radius, half extent or scaled mesh extent
inline constexpr double kMinSizeM = 1e-4;                    // 0.1 mm: below, Bullet's margins dominate
inline constexpr double kMaxCoordinateM = 100'000;           // any position (single-precision Bullet: 1 cm there)
inline constexpr double kMaxSpeedMps = 1'000;
inline constexpr double kMaxAngularSpeedRadps = 1'000;
inline constexpr double kMinMassKg = 1e-6;
inline constexpr double kMaxMassKg = 1e6;
inline constexpr double kMaxFriction = 10;                   // Bullet clamps combined friction to 10
inline constexpr double kMaxHistoryNs = 60'000'000'000;      // 60 s of substep states
inline constexpr int kMinSubstepHz = 30;
inline constexpr int kMaxSubstepHz = 20'000;
inline constexpr int64_t kMaxSubstepsPerAdvance = 10'000'000;
inline constexpr int kMaxSolverIterations = 1'000;

}  // namespace arpipe::physics_limits
